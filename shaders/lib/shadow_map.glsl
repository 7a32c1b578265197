// shading.glsl's light_visibility() from the frame's shadow maps: percentage-closer filtering
// of the light's own map at a view-space point, offset along its normal against acne. A
// directional or spot light reads its layer of the 2D array (an orthographic or perspective
// map), a point light its cube of the cube-map array; the lights buffer says which
// (LightData.shadow, passes/shadow_map.h); a light without one is unshadowed.
// Needs frame_uniforms.glsl, lights.glsl; the including shader defines SHADOWS (0 or 1) and,
// with SHADOWS, SHADOW_MAPS and SHADOW_CUBES (0 or 1: the frame has layers, cubes;
// ShadowMapPass::add_defines), and binds the maps by name (TEXTURE_SHADOW_MAP, TEXTURE_SHADOW_CUBES:
// ShadowMapPass::reads).

#if SHADOWS
#if SHADOW_MAPS
layout(binding = TEXTURE_SHADOW_MAP) uniform sampler2DArrayShadow u_shadow_map;

// The (2r+1)^2 taps of a PCF of radius r, each a 2x2 bilinearly filtered compare (hardware PCF),
// weight the (2r+2)^2 texels around the point separably: per axis 1-f, 1, ..., 1, f, with f the
// point's bilinear fraction. The same sum from (r+1)^2 taps, each covering a pair of
// texels per axis at the position that gives the pair's two weights as its bilinear weights
// (w0, w1 -> fraction w1 / (w0 + w1), tap weight w0 + w1): 4 taps instead of 9 for r = 1.
float shadow_map_visibility(LightData light, vec3 p_view, vec3 n_view) {
    vec3 p = p_view + n_view * (light.shadow.z * frame.shadow.z);  // texel size x offset in texels
    vec4 s4 = light.view_to_shadow * vec4(p, 1.0);  // w = 1 for a directional light's orthographic map
    if (s4.w <= 0.0) return 1.0;                      // behind a spot light: its cone lights nothing there
    vec3 s = s4.xyz / s4.w;
    if (any(lessThan(s, vec3(0.0))) || any(greaterThan(s, vec3(1.0)))) return 1.0;
#ifdef SHADOW_PCF_RADIUS
    const int r = SHADOW_PCF_RADIUS;  // compiled in (passes/lighting.cpp): the loops unroll
#else
    int r = int(frame.shadow.w);
#endif
    float layer = light.shadow.x;
    vec2 size = vec2(textureSize(u_shadow_map, 0).xy);
    vec2 t = s.xy * size - 0.5;  // texel i's centre is at i + 0.5
    vec2 base = floor(t);
    vec2 f = t - base;
    float lit = 0.0;
    for (int j = 0; j <= r; ++j) {
        float y0 = j == 0 ? 1.0 - f.y : 1.0, y1 = j == r ? f.y : 1.0;
        float y = base.y + float(2 * j - r) + 0.5 + y1 / (y0 + y1);
        for (int i = 0; i <= r; ++i) {
            float x0 = i == 0 ? 1.0 - f.x : 1.0, x1 = i == r ? f.x : 1.0;
            float x = base.x + float(2 * i - r) + 0.5 + x1 / (x0 + x1);
            lit += (x0 + x1) * (y0 + y1) * texture(u_shadow_map, vec4(vec2(x, y) / size, layer, s.z));
        }
    }
    return lit / float((2 * r + 1) * (2 * r + 1));
}
#endif

#if SHADOW_CUBES
layout(binding = TEXTURE_SHADOW_CUBES) uniform samplerCubeArrayShadow u_shadow_cubes;

// A point light's cube: the vector d from the light to the point (world axes) picks the face
// and the texel, and the point's depth in that face is the face's perspective depth of its
// distance along the major axis m = max |d_i| (the 90-degree faces share near n and far f):
// depth = (f + n) / (2 (f - n)) - f n / ((f - n) m) + 1/2, the window depth the pass rendered.
// PCF: (r+1)^2 hardware-filtered taps, 2 texels apart across d (a texel spans 2 m / size of
// world at the point), covering the (2r+2)^2 texels around it as the layers' filter does, with
// equal weights, each compared at its own depth; the normal offset is one texel at the point's
// distance times the setting. Faces are filtered each on its own (GL's seamless cube filtering
// is a global switch the probes' lookups would also see): a tap at a face's edge clamps there.
float shadow_cube_visibility(LightData light, vec3 p_view, vec3 n_view) {
    float size = float(textureSize(u_shadow_cubes, 0).x);
    vec3 d0 = (light.view_to_shadow * vec4(p_view, 1.0)).xyz;
    float m0 = max(max(abs(d0.x), abs(d0.y)), abs(d0.z));
    vec3 p = p_view + n_view * (2.0 * m0 / size * frame.shadow.z);
    vec3 d = (light.view_to_shadow * vec4(p, 1.0)).xyz;
    float m = max(max(abs(d.x), abs(d.y)), abs(d.z));
    float n = light.shadow.z, f = light.shadow.w;
    if (m <= n) return 1.0;  // nearer the light than its faces reach: nothing is drawn there
    float depth = 0.5 * (f + n) / (f - n) - f * n / ((f - n) * m) + 0.5;
    if (depth >= 1.0) return 1.0;  // beyond the far plane (outside the scene's bounds)
#ifdef SHADOW_PCF_RADIUS
    const int r = SHADOW_PCF_RADIUS;
#else
    int r = int(frame.shadow.w);
#endif
    float cube = light.shadow.y;
    // Two axes across d, scaled to one texel at the point.
    vec3 a = abs(d.y) < 0.99 * length(d) ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 u = normalize(cross(d, a));
    vec3 v = cross(normalize(d), u);
    float texel = 2.0 * m / size;
    float lit = 0.0;
    for (int j = 0; j <= r; ++j)
        for (int i = 0; i <= r; ++i) {
            vec3 dir = d + (float(2 * i - r) * u + float(2 * j - r) * v) * texel;
            // The tap's own depth in the face its direction selects (at a face's edge a tap
            // may read the neighbouring face).
            float mt = max(max(abs(dir.x), abs(dir.y)), abs(dir.z));
            lit += texture(u_shadow_cubes, vec4(dir, cube), 0.5 * (f + n) / (f - n) - f * n / ((f - n) * mt) + 0.5);
        }
    return lit / float((r + 1) * (r + 1));
}
#endif

float light_visibility(LightData light, vec3 p_view, vec3 n_view, vec3 l_view, float light_distance) {
#if SHADOW_MAPS
    if (light.shadow.x >= 0.0) return shadow_map_visibility(light, p_view, n_view);
#endif
#if SHADOW_CUBES
    if (light.shadow.y >= 0.0) return shadow_cube_visibility(light, p_view, n_view);
#endif
    return 1.0;
}
#else
float light_visibility(LightData light, vec3 p_view, vec3 n_view, vec3 l_view, float light_distance) { return 1.0; }
#endif
