// The covered tiles of the deep G-buffer (issue 13): which 8x8-pixel tiles of each layer hold a
// surface, marked by the peeling's shading pass (passes/depth_peel.frag), then compacted into
// a list that the lighting pass dispatches over indirectly (passes/lighting.comp), so that
// empty tiles of the deeper layers cost no invocation: llvmpipe runs every lane of a SIMD
// vector through both sides of a branch, so an early exit for an empty texel saves nothing.
// One buffer (passes/depth_peel.cpp clears it each frame):
//   covered_header  x: tiles in the list (the indirect dispatch's group count), y, z: 1
//   covered_tile[i] for i < layers * tiles: 1 where tile i (layer-major, rows of tiles) is covered;
//                   then the list: the covered tiles' indices, in no particular order.
#define COVERED_TILE_SIZE 8

layout(std430, binding = 14) coherent buffer CoveredTiles {
    uvec4 covered_header;
    uint covered_tile[];
};

ivec2 covered_tile_grid() {
    return (ivec2(frame.viewport.xy) + COVERED_TILE_SIZE - 1) / COVERED_TILE_SIZE;
}
