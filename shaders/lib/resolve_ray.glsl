// What a resolve needs of one ray (seed 000, 2.4): the radiance it brings and its weight, and
// where it went (its hit point, or its direction if it missed) with the pdf it was drawn with,
// shared by the resolve's tile fill (passes/resolve.comp, shared memory) and by resolve_fetch
// (passes/resolve_fetch.comp, the same data into textures where shared memory is the slower
// path, as on llvmpipe).
// Declares the inputs both bind alike (passes/resolve.cpp, bind_ray_inputs); needs
// frame_uniforms, depth_convention, ssr_settings, gbuffer, environment and input_fetch.

// By the names ResolvePass::ray_units gives; with FETCH_BY_IMAGE the float inputs are images.
INPUT_ARRAY(u_hit, TEXTURE_RAYS_HIT, IMAGE_RAYS_HIT, rgba32f);
INPUT_ARRAY(u_sample, TEXTURE_RAYS_SAMPLE, IMAGE_RAYS_SAMPLE, rgba32f);
INPUT_ARRAY(u_direction, TEXTURE_RAYS_DIRECTION, IMAGE_RAYS_DIRECTION, rgba32f);
INPUT_ARRAY(u_lit, TEXTURE_LIT, IMAGE_LIT, rgba16f);
INPUT_ARRAY(u_linear_depth, TEXTURE_LINEAR_DEPTH, IMAGE_LINEAR_DEPTH, r32f);
layout(binding = TEXTURE_GBUFFER_ALBEDO) uniform sampler2DArray u_albedo;
INPUT_ARRAY(u_normal, TEXTURE_GBUFFER_NORMAL, IMAGE_GBUFFER_NORMAL, rgba16f);
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;

#if (defined(BOUNCES_HISTORY) && BOUNCES_HISTORY) || (defined(TEMPORAL_RAY_REUSE) && TEMPORAL_RAY_REUSE)
layout(binding = TEXTURE_REPROJECTION) uniform sampler2D u_reprojection;  // reproject pass: xy previous pixel, z valid
#endif

#if defined(BOUNCES_HISTORY) && BOUNCES_HISTORY
// Multiple bounces over frames (seed 002, 4.6.4): a ray that hits layer 0 brings the previous
// frame's final colour at the hit's reprojected position, which already holds that surface's
// own reflection, instead of this frame's lit colour; each frame adds one bounce.
layout(binding = TEXTURE_PREVIOUS_COLOR) uniform sampler2D u_previous_color;
uniform int u_has_history;

vec3 previous_final(ivec2 hp, vec3 lit) {
    vec4 r = texelFetch(u_reprojection, hp, 0);
    if (u_has_history == 0 || r.z < 0.5) return lit;
    ivec2 size = textureSize(u_previous_color, 0);
    vec2 t = r.xy - 0.5;
    ivec2 b = ivec2(floor(t));
    vec2 f = t - vec2(b);
    vec3 c00 = texelFetch(u_previous_color, clamp(b, ivec2(0), size - 1), 0).rgb;
    vec3 c10 = texelFetch(u_previous_color, clamp(b + ivec2(1, 0), ivec2(0), size - 1), 0).rgb;
    vec3 c01 = texelFetch(u_previous_color, clamp(b + ivec2(0, 1), ivec2(0), size - 1), 0).rgb;
    vec3 c11 = texelFetch(u_previous_color, clamp(b + ivec2(1, 1), ivec2(0), size - 1), 0).rgb;
    return mix(mix(c00, c10, f.x), mix(c01, c11, f.x), f.y);
}
#endif

#if defined(RAY_RADIANCE) && RAY_RADIANCE
// Rays the BVH traced (trace_bvh.comp) bring its radiance (rgb) and hit distance
// (a >= 0; -1: the BVH found nothing; -2: not traced by the BVH). It stands where the
// environment stood: a screen-space miss brings it, a faded hit fades toward it.
INPUT_ARRAY(u_ray_radiance, TEXTURE_RAYS_RADIANCE, IMAGE_RAYS_RADIANCE, rgba32f);
#endif

GSample gsample(ivec2 p) {
    return gbuffer_decode(texelFetch(u_albedo, ivec3(p, 0), 0), FETCH(u_normal, ivec3(p, 0)),
                          texelFetch(u_material, ivec3(p, 0), 0));
}

vec3 view_pos(ivec2 p) {
    return view_position(vec2(p) + 0.5, FETCH(u_linear_depth, ivec3(p, 0)).r);
}

vec3 environment_view(vec3 dir_view) {
    return environment_radiance(normalize(mat3(frame.inv_view) * dir_view));
}

// What a ray screen space did not resolve brings: the environment along it, or nothing
// (fallback "none", to measure what screen space alone finds).
vec3 unresolved_radiance(vec3 dir_view) {
#if defined(FALLBACK_NONE) && FALLBACK_NONE
    return vec3(0.0);
#else
    return environment_view(dir_view);
#endif
}

// One ray's contribution: the radiance it brings (rgb) and its weight (a); its view direction
// and the distance from `origin` to its hit (w; -1: a miss) and its pdf.
struct RayResult {
    vec4 color;
    vec4 direction;
    float pdf;
};

RayResult fetch_ray(ivec2 q, int r, vec3 origin, ivec2 size) {
    vec4 hit = FETCH(u_hit, ivec3(q, r));
    vec4 smp = FETCH(u_sample, ivec3(q, r));
    vec3 dir = FETCH(u_direction, ivec3(q, r)).xyz;
    // What the ray brings where screen space did not resolve it; a hit at full fade weight
    // (hit.w = 1, most hits) never needs it (the environment costs more than the
    // hit's own fetch).
    bool opaque_hit = hit.z > 0.5 && hit.w >= 1.0;
    vec3 c = vec3(0.0);
    float dist = -1.0;
#if defined(RAY_RADIANCE) && RAY_RADIANCE
    vec4 traced = FETCH(u_ray_radiance, ivec3(q, r));
    if (traced.a > -1.5) {
        c = traced.rgb;
        dist = traced.a;
    } else if (!opaque_hit) {
        c = unresolved_radiance(dir);
    }
#else
    if (!opaque_hit) c = unresolved_radiance(dir);
#endif
    bool screen_hit = hit.z > 0.5;
#if defined(RAY_RADIANCE_EXACT) && RAY_RADIANCE_EXACT
    // A faded hit the BVH retraced brings the BVH's radiance alone: the exact answer for the
    // whole ray, not a blend with the doubtful screen-space hit it replaces.
    if (!opaque_hit && traced.a > -1.5) screen_hit = false;
#endif
    if (screen_hit) {
        ivec3 hp = ivec3(clamp(ivec2(hit.xy), ivec2(0), size - 1), int(hit.z) - 1);
        vec3 lit = FETCH(u_lit, hp).rgb;
#if defined(RAY_RADIANCE) && RAY_RADIANCE
        // The fallback shades the hits it keeps from the ray's origin (trace_bvh.comp: a >= 0
        // on a full-strength screen hit): that radiance replaces the camera's view of the hit.
        if (opaque_hit && traced.a > -1.5) lit = traced.rgb;
#endif
#if defined(BOUNCES_HISTORY) && BOUNCES_HISTORY
        if (hp.z == 0) lit = previous_final(hp.xy, lit);
#endif
        c = opaque_hit ? lit : mix(c, lit, hit.w);
        dist = distance(view_position(hit.xy, FETCH(u_linear_depth, hp).r), origin);
    }
    RayResult res;
    res.color = vec4(c, smp.x);
    res.direction = vec4(dir, dist);
    res.pdf = smp.y;
    return res;
}

// The tile entry of ray r of trace pixel q whose surface lies at view position `origin`: the
// colour it brings with its weight (a; 0: no ray), and its target: the view position of its hit
// (xyz, w = its pdf) or, for a miss, its direction (w = -pdf), so that a pixel p reusing it
// looks along xyz - p or xyz (a pdf of 0, never reweighted, needs no flag).
void reusable_ray(ivec2 q, int r, vec3 origin, bool traced, ivec2 size, out vec4 color, out vec4 target) {
    color = vec4(0.0);
    target = vec4(0.0, 0.0, 1.0, 0.0);
    if (traced) {
        RayResult ray = fetch_ray(q, r, origin, size);
        vec4 d = ray.direction;
        color = ray.color;
        target = d.w >= 0.0 ? vec4(origin + d.xyz * d.w, ray.pdf) : vec4(d.xyz, -ray.pdf);
    }
}
