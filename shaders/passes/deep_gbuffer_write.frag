#version 450 core
// deep_gbuffer write: layer u_layer of the G-buffer from the fragments the selection kept
// (passes/deep_gbuffer_select.comp). The stored outputs go through the same framebuffer
// formats (sRGB encoding, half floats, unorm8) as peeling's shading pass, and the stored window
// depth is written as the fragment depth, so every texel equals the peeled one bit for bit.
// It also marks the covered tiles and layer 0's reflective regions as that pass does
// (lib/covered_tiles.glsl).
#include "../lib/frame_uniforms.glsl"
#include "../lib/fragment_lists.glsl"
#include "../lib/covered_tiles.glsl"

layout(std430, binding = 19) readonly buffer KeptFragments { uint kept[]; };

uniform int u_layer;

layout(location = 0) out vec4 o_albedo_metallic;
layout(location = 1) out vec4 o_normal_roughness;
layout(location = 2) out vec4 o_material;

void main() {
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 p = ivec2(gl_FragCoord.xy);
    uint s = kept[uint(u_layer) * uint(size.x * size.y) + uint(p.y * size.x + p.x)];
    if (s == FRAGMENT_NONE) discard;
    ListFragment f = fragments[s];
    o_albedo_metallic = f.albedo_metallic;
    o_normal_roughness = f.normal_roughness;
    o_material = f.material;
    gl_FragDepth = f.depth;
    ivec2 grid = covered_tile_grid();
    ivec2 tile = p / COVERED_TILE_SIZE;
    covered_tile[(u_layer * grid.y + tile.y) * grid.x + tile.x] = 1u;
    if (u_layer == 0 && (f.draw_flags & 0x80000000u) != 0u) {
        uint base = classify_regions_base(int(frame.clip.z));
        ivec2 regions = classify_region_grid();
        ivec2 region = p / CLASSIFY_REGION_SIZE;
        uint i = uint(region.y * regions.x + region.x);
        if (covered_tile[base + 4u + i] == 0u && atomicExchange(covered_tile[base + 4u + i], 1u) == 0u) {
            uint n = atomicAdd(covered_tile[base], 1u);
            covered_tile[base + 4u + uint(regions.x * regions.y) + n] = i;
        }
    }
}
