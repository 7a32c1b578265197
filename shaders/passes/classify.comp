#version 450 core
// classify: which pixels need rays and which receive a reflection. Seed 000 4.1
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
layout(binding = IMAGE_REFLECTION, rgba16f) writeonly uniform image2D o_reflection;
#endif

// The groups run over the 32x32 regions where the peeling drew a reflective surface
// in layer 0 (lib/covered_tiles.glsl, indirect dispatch), not over the whole image.
#include "../lib/covered_tiles.glsl"

// Llvmpipe pays a fixed cost per work group (~2 us, measured: an empty 8x8 classify
// cost 2 ms at 320x180), so the groups are CLASSIFY_GROUP wide.
#ifndef CLASSIFY_GROUP_X
#define CLASSIFY_GROUP_X 8
#define CLASSIFY_GROUP_Y 8
#endif
// One invocation per CLASSIFY_BLOCK x CLASSIFY_BLOCK pixels (2 or 4: a bit mask holds the
// block's list entries, gathers read 2x2): llvmpipe pays a fixed cost per invocation
// (cpp/passes/classify.cpp).
#ifndef CLASSIFY_BLOCK
#define CLASSIFY_BLOCK 4
#endif
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = TEXTURE_LINEAR_DEPTH) uniform sampler2DArray u_linear_depth;
layout(binding = TEXTURE_GBUFFER_ALBEDO) uniform sampler2DArray u_albedo;
layout(binding = TEXTURE_GBUFFER_NORMAL) uniform sampler2DArray u_normal;
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;

uniform int u_rays;  // rays per trace pixel (the ray textures' layers)

// Whether full-resolution column (row) x is the origin column of a trace column (origin_pixel).
bool origin_line(int x, int trace_size, int image_size) {
    int q = x / ssr.downscale;
    return x < image_size && q < trace_size && min(q * ssr.downscale + ssr.downscale / 2, image_size - 1) == x;
}

void main() {
    const int B = CLASSIFY_BLOCK;
    ivec2 size = ivec2(frame.viewport.xy);
    // This group's region: every pixel of the others is known not to reflect, so that (with
    // their "no ray" and "no reflection" cleared) they need no invocation at all.
    uint regions_base = classify_regions_base(int(frame.clip.z));
    ivec2 regions = classify_region_grid();
    int region = int(covered_tile[regions_base + 4u + uint(regions.x * regions.y) + gl_WorkGroupID.x]);
    ivec2 group_origin = ivec2(region % regions.x, region / regions.x) * CLASSIFY_REGION_SIZE;
    // The trace pixels examined (those whose origin pixel is in this group), counted once per
    // group rather than by one atomic per pixel on the same counter.
    if (gl_LocalInvocationIndex == 0u) {
        ivec2 o = group_origin;
        uint nx = 0u, ny = 0u;
        for (int i = 0; i < 8 * B; ++i) {
            if (origin_line(o.x + i, ssr.trace_width, size.x)) ++nx;
            if (origin_line(o.y + i, ssr.trace_height, size.y)) ++ny;
        }
        if (nx * ny > 0u) atomicAdd(ray_list.classified, nx * ny);
    }
    ivec2 block = group_origin + ivec2(gl_LocalInvocationID.xy) * B;
    if (any(greaterThanEqual(block, size))) return;
    uint traced = 0u;     // bit i: pixel i of the block joins the ray list
    uint receivers = 0u;  // bit i: pixel i of the block receives rays (is_reflective)
    uint environment = 0u;
    // The reflectivity (material.r; 0 where no surface is) of the block's pixels first, 2x2 per
    // gather: most blocks of most frames hold no reflective pixel and stop here (four
    // gathers cost llvmpipe half of sixteen texelFetch). A gather at the corner shared by texels
    // (x, y) .. (x + 1, y + 1) returns their r as (x, y+1), (x+1, y+1), (x+1, y), (x, y).
    float reflectivity[B * B];
    vec2 inv_size = 1.0 / vec2(size);
    bool any_reflective = false;
    for (int j = 0; j < B; j += 2) {
        for (int i = 0; i < B; i += 2) {
            vec4 r = textureGather(u_material, vec3((vec2(block + ivec2(i, j)) + 1.0) * inv_size, 0.0), 0);
            reflectivity[j * B + i] = r.w;
            reflectivity[j * B + i + 1] = r.z;
            reflectivity[(j + 1) * B + i] = r.x;
            reflectivity[(j + 1) * B + i + 1] = r.y;
            any_reflective = any_reflective || any(greaterThan(r, vec4(0.0)));
        }
    }
    if (!any_reflective) return;
    for (int i = 0; i < B * B; ++i) {
        ivec2 p = block + ivec2(i % B, i / B);
        if (reflectivity[i] <= 0.0 || any(greaterThanEqual(p, size))) continue;
        vec4 material = texelFetch(u_material, ivec3(p, 0), 0);
        if (!(material.g > 0.5 && material.r > 0.0)) continue;
        // No albedo: nothing here reads it (the ray's direction and weight depend on the normal
        // and roughness only), and llvmpipe's sRGB fetch is dear.
        GSample g = gbuffer_decode(vec4(0.0), texelFetch(u_normal, ivec3(p, 0), 0), material);
        vec3 pos = view_position(vec2(p) + 0.5, texelFetch(u_linear_depth, ivec3(p, 0), 0).r);
        if (!is_reflective(g)) {  // rougher than the cutoff: the environment, no ray
#if RESOLVE_LISTS
            imageStore(o_reflection, p, vec4(non_receiver_reflection(g, normalize(-pos)), 1.0));
            ++environment;
#endif
            continue;
        }
        receivers |= 1u << uint(i);
        if (!origin_line(p.x, ssr.trace_width, size.x) || !origin_line(p.y, ssr.trace_height, size.y)) continue;
        float facing = dot(g.normal, normalize(-pos));
        if (!(facing > max(1e-4, float(CLASSIFY_FACING)))) continue;  // no ray: the cleared zeros
        ivec2 q = p / ssr.downscale;
#if RAY_LIST_PER_RAY
        // One entry per ray the pixel traces (adaptive rays); the slots past them get what the
        // full-screen trace writes for them (weight 0 of a pixel that traces).
        int n = rays_for_roughness(g.roughness);
        uint first = atomicAdd(ray_list.count, uint(n));
        atomicAdd(ray_list.listed_pixels, 1u);
        for (int k = 0; k < n; ++k) {
            ray_list.pixels[2u * (first + uint(k))] = pack_pixel(q);
            ray_list.pixels[2u * (first + uint(k)) + 1u] = uint(k);
            ray_list_open_group(first + uint(k));
        }
        for (int r = n; r < u_rays; ++r) store_ray(ivec3(q, r), generate_ray(g, pos, q, r), true, vec4(0.0), 0.0);
#else
        traced |= 1u << uint(i);
#endif
    }
#if !RAY_LIST_PER_RAY
    // The block's ray list entries, consecutive: one atomic.
    if (traced != 0u) {
        uint k = atomicAdd(ray_list.count, uint(bitCount(traced)));
        for (int i = 0; i < B * B; ++i) {
            if ((traced & (1u << uint(i))) == 0u) continue;
            ray_list.pixels[k] = pack_pixel((block + ivec2(i % B, i / B)) / ssr.downscale);
            ray_list_open_group(k++);
        }
    }
#endif
#if RESOLVE_LISTS
    if (environment > 0u) atomicAdd(resolve_list.environment_pixels, environment);
    if (receivers != 0u) {
#if RESOLVE_LIST_PIXELS
        uint k = resolve_list_reserve(uint(bitCount(receivers)), 64u);
        for (int i = 0; i < B * B; ++i)
            if ((receivers & (1u << uint(i))) != 0u) resolve_list.entries[k++] = resolve_list_pack(block + ivec2(i % B, i / B));
#else
        resolve_list_add_tile_of(block, size.x);  // a block lies in one 16x16 tile (B divides 16)
#endif
    }
#endif
}
