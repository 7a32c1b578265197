#version 450 core
// resolve_fetch: the resolve's tile fill (seed 000, 2.4: every ray's radiance and weight, and where
// it went, fetched once and reused by every pixel within reuse_radius) written to two textures
// instead of the resolve's shared memory. Llvmpipe (Mesa 22.3) loads shared memory one
// lane and one component at a time, each through the stack (a perf profile of the thesis
// configuration's resolve: ~60 % of the pass in those loads), while an imageLoad is inline; so
// where the passes read their inputs by imageLoad (FETCH_BY_IMAGE, the CPU device) the resolve
// reads its neighbours' rays from these textures (RESOLVE_SHARED_TILE 0) and this pass fills them,
// each ray once (the tiles' aprons fetched some twice). On a GPU the shared tile stays.
//   o_ray_color  RGBA32F: radiance the ray brings (rgb), its weight (a; 0: no ray)
//   o_ray_target RGBA32F: view position of its hit (xyz, w = pdf), or its direction (w = -pdf)
// Every (trace pixel, ray) slot is written; a pixel that traced nothing gets zeros, as in the tile.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/ssr_settings.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/environment.glsl"
#include "../lib/input_fetch.glsl"
#include "../lib/resolve_ray.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = IMAGE_RESOLVE_RAY_COLOR, rgba32f) writeonly uniform image2DArray o_ray_color;
layout(binding = IMAGE_RESOLVE_RAY_TARGET, rgba32f) writeonly uniform image2DArray o_ray_target;

void main() {
    ivec3 id = ivec3(gl_GlobalInvocationID);  // (trace pixel, ray)
    ivec2 size = ivec2(frame.viewport.xy);
    int s = ssr.downscale;
    if (id.x >= ssr.trace_width || id.y >= ssr.trace_height) return;
    ivec2 op = min(id.xy * s + s / 2, size - 1);  // the full-resolution pixel the rays start from
    bool traced = FETCH(u_sample, ivec3(id.xy, 0)).w > 0.5;
    vec4 color, target;
    reusable_ray(id.xy, id.z, view_pos(op), traced, size, color, target);
    imageStore(o_ray_color, id, color);
    imageStore(o_ray_target, id, target);
}
