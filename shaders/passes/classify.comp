#version 450 core
// classify (issue 11): which trace pixels need rays. Seed 000 4.1 and seed 003 skip surfaces
// above the roughness cutoff or without reflectivity (is_reflective); seed 004's "early out
// by checking roughness and angle" adds the facing test: a surface seen edge-on or from
// behind gets no ray (generate_ray's own test; CLASSIFY_FACING raises its threshold). The
// pixels that pass are appended to the ray list (ray_list.glsl) for the trace pass's
// indirect dispatch; the others get the trace pass's "no ray" outputs here, exactly what the
// full-screen trace writes for them, so every later pass reads the same textures.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/ssr_settings.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/brdf.glsl"
#include "../lib/random.glsl"
#include "../lib/ggx_sampling.glsl"
#include "../lib/ray_generation.glsl"
#include "../lib/trace_common.glsl"
#include "../lib/ray_list.glsl"

#ifndef CLASSIFY_FACING
#define CLASSIFY_FACING 0.0
#endif

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler2DArray u_linear_depth;
layout(binding = 1) uniform sampler2DArray u_albedo;
layout(binding = 2) uniform sampler2DArray u_normal;
layout(binding = 3) uniform sampler2DArray u_material;

uniform int u_rays;  // rays per trace pixel (the ray textures' layers)

void main() {
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    // The examined pixels, counted once per group (the group's share of the image) rather than
    // by one atomic per pixel on the same counter.
    if (gl_LocalInvocationIndex == 0u) {
        ivec2 o = ivec2(gl_WorkGroupID.xy) * 8;
        ivec2 n = min(ivec2(8), ivec2(ssr.trace_width, ssr.trace_height) - o);
        atomicAdd(ray_list.classified, uint(n.x * n.y));
    }
    if (q.x >= ssr.trace_width || q.y >= ssr.trace_height) return;
    ivec2 p = origin_pixel(q);
    GSample g = gbuffer_decode(texelFetch(u_albedo, ivec3(p, 0), 0), texelFetch(u_normal, ivec3(p, 0), 0),
                               texelFetch(u_material, ivec3(p, 0), 0));
    vec3 pos = view_position(vec2(p) + 0.5, texelFetch(u_linear_depth, ivec3(p, 0), 0).r);
    bool reflective = is_reflective(g);
    float facing = dot(g.normal, normalize(-pos));
    if (reflective && facing > max(1e-4, float(CLASSIFY_FACING))) {
#if RAY_LIST_PER_RAY
        // One entry per ray the pixel traces (adaptive rays); the slots past them get the
        // trace's "no ray" here, as the full-screen trace writes them.
        int n = rays_for_roughness(g.roughness);
        uint i = atomicAdd(ray_list.count, uint(n));
        atomicAdd(ray_list.listed_pixels, 1u);
        for (int k = 0; k < n; ++k) {
            ray_list.pixels[2u * (i + uint(k))] = pack_pixel(q);
            ray_list.pixels[2u * (i + uint(k)) + 1u] = uint(k);
            ray_list_open_group(i + uint(k));
        }
        for (int r = n; r < u_rays; ++r) store_ray(ivec3(q, r), generate_ray(g, pos, q, r), true, vec4(0.0), 0.0);
#else
        uint i = atomicAdd(ray_list.count, 1u);
        ray_list.pixels[i] = pack_pixel(q);
        ray_list_open_group(i);
#endif
        return;
    }
    // No ray: generate_ray returns its "no ray" (weight 0) for these pixels.
    for (int r = 0; r < u_rays; ++r) {
        ReflectionRay ray = generate_ray(g, pos, q, r);
        if (ray.weight > 0.0) {  // a CLASSIFY_FACING above generate_ray's own test drops this ray
            ray.weight = 0.0;
            ray.pdf = 0.0;
        }
        store_ray(ivec3(q, r), ray, reflective, vec4(0.0), 0.0);
    }
}
