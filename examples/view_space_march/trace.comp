#version 450 core
// A view-space ray march with a binary-search refinement, the screen-space reflection of
// CryENGINE 3 as Sousa, Kasyan and Schulz describe it ("Secrets of CryENGINE 3 Graphics
// Technology", SIGGRAPH 2011 course): the reflected ray advances in view space by a fixed
// number of steps whose length grows with the distance of its origin; each step is projected to
// the screen and compared with the depth buffer; the first sample behind the surface (by less
// than a thickness) is refined by halving the last step a few times. It steps in view space,
// not per pixel as ssrlab's DDA (McGuire & Mara 2014) or per cell as its Hi-Z walk: a cheap
// march that can step over thin objects. Written from that description; front layer only.
//
// The GLSL contract of a trace pass (docs/guide/glsl-contract.md): the G-buffer at texture units
// 0-3 (INPUT_ARRAY for the float ones), rays.* written by store_ray, one invocation per
// (trace pixel, ray) in 8x8 groups, or classify's list with RAY_LIST; parameters as u_<name>;
// loops bounded by ssr.max_steps.
#include "lib/frame_uniforms.glsl"
#include "lib/depth_convention.glsl"
#include "lib/ssr_settings.glsl"
#include "lib/gbuffer.glsl"
#include "lib/brdf.glsl"
#include "lib/random.glsl"
#include "lib/ggx_sampling.glsl"
#include "lib/ray_generation.glsl"
#include "lib/screen_ray.glsl"
#include "lib/trace_common.glsl"
#if RAY_LIST
#include "lib/ray_list.glsl"
#endif
#include "lib/input_fetch.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

INPUT_ARRAY(u_linear_depth, 0, 3, r32f);
layout(binding = 1) uniform sampler2DArray u_albedo;
INPUT_ARRAY(u_normal, 2, 4, rgba16f);
layout(binding = 3) uniform sampler2DArray u_material;

uniform int u_steps;          // march steps (at most Settings.max_steps)
uniform float u_step_scale;   // step length as a fraction of the origin's view depth
uniform int u_refine;         // binary-search halvings after the first sample behind a surface
uniform float u_thickness;    // a surface is taken as this fraction of its depth thick

// View depth of the front surface at a view-space point's pixel; false off the screen.
bool scene_depth(vec3 p, out vec2 pixel, out float depth) {
    vec3 w = view_to_pixel(p);
    pixel = w.xy;
    depth = 0.0;
    if (any(lessThan(pixel, vec2(0.0))) || any(greaterThanEqual(pixel, frame.viewport.xy))) return false;
    depth = FETCH(u_linear_depth, ivec3(ivec2(pixel), 0)).r;
    return true;
}

void main() {
#if RAY_LIST
    ivec3 id;
    if (!ray_list_entry(id)) return;
#else
    ivec3 id = ivec3(gl_GlobalInvocationID);
    if (id.x >= ssr.trace_width || id.y >= ssr.trace_height) return;
#endif
    ivec2 p = origin_pixel(id.xy);
    GSample g = gbuffer_decode(texelFetch(u_albedo, ivec3(p, 0), 0), FETCH(u_normal, ivec3(p, 0)),
                               texelFetch(u_material, ivec3(p, 0), 0));
    vec3 pos = view_position(vec2(p) + 0.5, FETCH(u_linear_depth, ivec3(p, 0)).r);
    ReflectionRay ray = generate_ray(g, pos, id.xy, id.z);
    vec4 hit = vec4(0.0);
    float fetches = 0.0;
    if (ray.weight > 0.0) {
        float len = ray_length_in_front_of_near(ray.origin, ray.dir, ssr.max_distance);
        float step_len = u_step_scale * max(-ray.origin.z, frame.clip.x);
        // A per-ray offset of the first step (the course's jitter against banding).
        float jitter = unit_float(pcg_hash(uint(id.x) * 9781u + uint(id.y) * 6271u + uint(id.z) * 26699u + ssr.seed));
        int steps = min(u_steps, ssr.max_steps);
        float t_prev = 0.0, t = step_len * jitter;
        bool found = false;
        for (int i = 0; i < steps && !found && t <= len; ++i) {
            t += step_len;
            vec2 pixel;
            float depth;
            vec3 q = ray.origin + ray.dir * min(t, len);
            if (!scene_depth(q, pixel, depth)) break;
            fetches += 1.0;
            float behind = -q.z - depth;
            found = depth > 0.0 && behind > 0.0 && behind < u_thickness * depth;
            if (!found) t_prev = t;
        }
        if (found) {
            // Halve the last step: keep the half whose end is still behind the surface.
            float lo = t_prev, hi = t;
            for (int k = 0; k < u_refine; ++k) {
                float mid = 0.5 * (lo + hi);
                vec2 pixel;
                float depth;
                scene_depth(ray.origin + ray.dir * mid, pixel, depth);
                fetches += 1.0;
                if (-(ray.origin.z + ray.dir.z * mid) > depth) hi = mid; else lo = mid;
            }
            vec2 pixel;
            float depth;
            vec3 q = ray.origin + ray.dir * hi;
            if (scene_depth(q, pixel, depth)) {
                vec3 hit_view = view_position(pixel, depth);
                hit = vec4(pixel, 1.0, hit_fade(pixel, ray.origin, ray.dir, hit_view));
            }
        }
    }
    store_ray(id, ray, is_reflective(g), hit, fetches);
}
