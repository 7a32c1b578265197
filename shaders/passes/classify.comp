#version 450 core
// classify (issue 11): which pixels need rays and which receive a reflection. Seed 000 4.1
// and seed 003 skip surfaces above the roughness cutoff or without reflectivity
// (is_reflective); seed 004's "early out by checking roughness and angle" adds the facing
// test: a surface seen edge-on or from behind gets no ray (generate_ray's own test;
// CLASSIFY_FACING raises its threshold). One invocation per full-resolution pixel, which
// fetches its material first and leaves at once where nothing reflects. Then:
// - the ray list (ray_list.glsl): a trace pixel joins it when this pixel is its origin pixel
//   (the centre of its downscale block) and passes the tests; the trace pass runs over the
//   list by indirect dispatch. "No ray" is all zeros: the pass cleared the ray textures
//   before this dispatch (cpp/passes/classify.cpp), so only a listed pixel's adaptive-ray
//   slots past its count are written here, as the full-screen trace writes them;
// - RESOLVE_LISTS: the resolve's list (resolve_list.glsl) of receiving pixels (own rays) or
//   of the 16x16 tiles holding one; a reflective pixel rougher than the cutoff gets the
//   environment here (non_receiver_reflection), every other non-receiver keeps the cleared 0.
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
#ifndef RESOLVE_LISTS
#define RESOLVE_LISTS 0
#endif

#if RESOLVE_LISTS
#include "../lib/environment.glsl"
#include "../lib/non_receiver.glsl"
#include "../lib/resolve_list.glsl"
layout(binding = 3, rgba16f) writeonly uniform image2D o_reflection;
#endif

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler2DArray u_linear_depth;
layout(binding = 1) uniform sampler2DArray u_albedo;
layout(binding = 2) uniform sampler2DArray u_normal;
layout(binding = 3) uniform sampler2DArray u_material;

uniform int u_rays;  // rays per trace pixel (the ray textures' layers)

// Whether full-resolution column (row) x is the origin column of a trace column (origin_pixel).
bool origin_line(int x, int trace_size, int image_size) {
    int q = x / ssr.downscale;
    return x < image_size && q < trace_size && min(q * ssr.downscale + ssr.downscale / 2, image_size - 1) == x;
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(frame.viewport.xy);
    // The trace pixels examined (those whose origin pixel is in this group), counted once per
    // group rather than by one atomic per pixel on the same counter.
    if (gl_LocalInvocationIndex == 0u) {
        ivec2 o = ivec2(gl_WorkGroupID.xy) * 8;
        uint nx = 0u, ny = 0u;
        for (int i = 0; i < 8; ++i) {
            if (origin_line(o.x + i, ssr.trace_width, size.x)) ++nx;
            if (origin_line(o.y + i, ssr.trace_height, size.y)) ++ny;
        }
        if (nx * ny > 0u) atomicAdd(ray_list.classified, nx * ny);
    }
    if (any(greaterThanEqual(p, size))) return;
    // The material first: most pixels of most frames leave here (no surface, no reflectivity).
    vec4 material = texelFetch(u_material, ivec3(p, 0), 0);
    if (!(material.g > 0.5 && material.r > 0.0)) return;
    GSample g = gbuffer_decode(texelFetch(u_albedo, ivec3(p, 0), 0), texelFetch(u_normal, ivec3(p, 0), 0), material);
    vec3 pos = view_position(vec2(p) + 0.5, texelFetch(u_linear_depth, ivec3(p, 0), 0).r);
    if (!is_reflective(g)) {  // rougher than the cutoff: the environment, no ray
#if RESOLVE_LISTS
        imageStore(o_reflection, p, vec4(non_receiver_reflection(g, normalize(-pos)), 1.0));
        atomicAdd(resolve_list.environment_pixels, 1u);
#endif
        return;
    }
#if RESOLVE_LISTS
    resolve_list_add_receiver(p, size.x);
#endif
    ivec2 q = p / ssr.downscale;
    if (!origin_line(p.x, ssr.trace_width, size.x) || !origin_line(p.y, ssr.trace_height, size.y)) return;
    float facing = dot(g.normal, normalize(-pos));
    if (!(facing > max(1e-4, float(CLASSIFY_FACING)))) return;  // no ray: the cleared zeros
#if RAY_LIST_PER_RAY
    // One entry per ray the pixel traces (adaptive rays); the slots past them get what the
    // full-screen trace writes for them (weight 0 of a pixel that traces).
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
}
