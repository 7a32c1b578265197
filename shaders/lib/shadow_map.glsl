// shading.glsl's light_visibility() from the frame's shadow map: percentage-closer filtering
// of the shadow-casting light's map (a directional light's orthographic one or a spot light's
// perspective one) at a view-space point, offset along its normal against acne, for the light
// that casts it; every other light is unshadowed.
// Needs frame_uniforms.glsl, lights.glsl; the including shader declares
//     layout(binding = N) uniform sampler2DShadow u_shadow_map;
// and defines SHADOWS (0 or 1).

#if SHADOWS
// The (2r+1)^2 taps of a PCF of radius r, each a 2x2 bilinearly filtered compare (hardware PCF),
// weight the (2r+2)^2 texels around the point separably: per axis 1-f, 1, ..., 1, f, with f the
// point's bilinear fraction. The same sum from (r+1)^2 taps, each covering a pair of
// texels per axis at the position that gives the pair's two weights as its bilinear weights
// (w0, w1 -> fraction w1 / (w0 + w1), tap weight w0 + w1): 4 taps instead of 9 for r = 1.
float shadow_visibility(vec3 p_view, vec3 n_view) {
    vec3 p = p_view + n_view * (frame.shadow.y * frame.shadow.z);  // texel size x offset in texels
    vec4 s4 = frame.view_to_shadow * vec4(p, 1.0);  // w = 1 for a directional light's orthographic map
    if (s4.w <= 0.0) return 1.0;                      // behind a spot light: its cone lights nothing there
    vec3 s = s4.xyz / s4.w;
    if (any(lessThan(s, vec3(0.0))) || any(greaterThan(s, vec3(1.0)))) return 1.0;
#ifdef SHADOW_PCF_RADIUS
    const int r = SHADOW_PCF_RADIUS;  // compiled in (passes/lighting.cpp): the loops unroll
#else
    int r = int(frame.shadow.w);
#endif
    vec2 size = vec2(textureSize(u_shadow_map, 0));
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
            lit += (x0 + x1) * (y0 + y1) * texture(u_shadow_map, vec3(vec2(x, y) / size, s.z));
        }
    }
    return lit / float((2 * r + 1) * (2 * r + 1));
}
#else
float shadow_visibility(vec3 p_view, vec3 n_view) { return 1.0; }
#endif

float light_visibility(LightData light, vec3 p_view, vec3 n_view, vec3 l_view, float light_distance) {
    return light.direction_shadow.w > 0.5 ? shadow_visibility(p_view, n_view) : 1.0;
}
