#version 450 core
// Lighting pass: shades every layer of the deep G-buffer (seed 000, 1.1.1 "lighting pass"),
// so that a reflection ray that hits layer k has a colour to fetch. Also writes each
// layer's linear view-space depth, which the tracers and the Python readback use.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/scene_data.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/brdf.glsl"
#include "../lib/lights.glsl"
#include "../lib/shading.glsl"
#include "../lib/gbuffer_emission.glsl"
#include "../lib/gbuffer_specular.glsl"

#include "../lib/covered_tiles.glsl"
#include "../lib/input_fetch.glsl"

#ifndef TILE_LIST
#define TILE_LIST 0  // 1: the compaction of the covered tiles into the list (passes/lighting.cpp)
#endif

uniform int u_tiles;  // layers x tiles per layer: where covered_tile[] holds the list

layout(binding = TEXTURE_GBUFFER_DEPTH) uniform sampler2DArray u_depth;
layout(binding = TEXTURE_GBUFFER_ALBEDO) uniform sampler2DArray u_albedo;
INPUT_ARRAY(u_normal, TEXTURE_GBUFFER_NORMAL, IMAGE_GBUFFER_NORMAL, rgba16f);
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;

layout(binding = IMAGE_LIT, rgba16f) writeonly uniform image2DArray o_lit;
layout(binding = IMAGE_LINEAR_DEPTH, r32f) writeonly uniform image2DArray o_linear_depth;

#include "../lib/shadow_map.glsl"

#if TILE_LIST
layout(local_size_x = 64) in;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uint(u_tiles) || covered_tile[i] == 0u) return;
    covered_tile[uint(u_tiles) + atomicAdd(covered_header.x, 1u)] = i;
}
#else
layout(local_size_x = COVERED_TILE_SIZE, local_size_y = COVERED_TILE_SIZE, local_size_z = 1) in;

void main() {
    lights_load();  // before any control flow (lib/lights.glsl)
    // Only covered tiles are dispatched; the rest of every layer was cleared to what an
    // uncovered texel gets below.
    ivec2 grid = covered_tile_grid();
    int entry = int(covered_tile[uint(u_tiles) + gl_WorkGroupID.x]);
    int layer = entry / (grid.x * grid.y), tile = entry % (grid.x * grid.y);
    ivec3 p = ivec3(ivec2(tile % grid.x, tile / grid.x) * COVERED_TILE_SIZE + ivec2(gl_LocalInvocationID.xy), layer);
    if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) return;

    GSample g = gbuffer_decode(texelFetch(u_albedo, p, 0), FETCH(u_normal, p), texelFetch(u_material, p, 0));
    if (!g.covered) {
        imageStore(o_linear_depth, p, vec4(frame.clip.y));  // nothing here: exactly the far plane
        imageStore(o_lit, p, vec4(0.0));
        return;
    }
    float z = linear_depth(texelFetch(u_depth, p, 0).r);
    imageStore(o_linear_depth, p, vec4(z));
    vec3 pos = view_position(vec2(p.xy) + 0.5, z);
    vec3 radiance = shade_surface(g, gbuffer_emission(p, g), gbuffer_dielectric_f0(p, g), pos, normalize(-pos));
    // Alpha: coverage and the reflectivity r for the composite (0.5 + r / 2 > 0; 0 where nothing is).
    imageStore(o_lit, p, vec4(radiance, 0.5 + 0.5 * g.reflectivity));
}
#endif
