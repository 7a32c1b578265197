// The covered tiles of the deep G-buffer: which 8x8-pixel tiles of each layer hold a
// surface, marked by the peeling's shading pass (passes/depth_peel.frag), then compacted into
// a list that the lighting pass dispatches over indirectly (passes/lighting.comp), so that
// empty tiles of the deeper layers cost no invocation: llvmpipe runs every lane of a SIMD
// vector through both sides of a branch, so an early exit for an empty texel saves nothing.
// One buffer (passes/depth_peel.cpp clears it each frame):
//   covered_header  x: tiles in the list (the indirect dispatch's group count), y, z: 1
//   covered_tile[i] for i < layers * tiles: 1 where tile i (layer-major, rows of tiles) is covered;
//                   then the list: the covered tiles' indices, in no particular order;
//   then the reflective regions of layer 0, from classify_regions_base():
//                   4 uints of indirect dispatch arguments (regions listed, 1, 1, 0), a flag per
//                   32x32-pixel region (1: layer 0 drew a surface with a reflectivity there), and
//                   the list of flagged regions, which the classify pass dispatches over: a frame
//                   without reflective pixels runs no classify group. Overdrawn fragments may flag
//                   a region needlessly, never miss one.
#define COVERED_TILE_SIZE 8
#define CLASSIFY_REGION_SIZE 32  // the classify pass's group footprint (8x8 invocations of 4x4 pixels)

layout(std430, binding = BUFFER_COVERED_TILES) coherent buffer CoveredTiles {
    uvec4 covered_header;
    uint covered_tile[];
};

// How flag_reflective_region reaches covered_tile[i]: an including shader may define
// COVERED_TILE_LOAD(i), COVERED_TILE_EXCHANGE(i, v), COVERED_TILE_ADD(i, v) and
// COVERED_TILE_STORE(i, v) itself (the CPU device: through an image buffer over the same storage,
// which llvmpipe reads inline, where a storage-buffer access is a loop over the lanes).
#ifndef COVERED_TILE_LOAD
#define COVERED_TILE_LOAD(i) covered_tile[i]
#define COVERED_TILE_EXCHANGE(i, v) atomicExchange(covered_tile[i], v)
#define COVERED_TILE_ADD(i, v) atomicAdd(covered_tile[i], v)
#define COVERED_TILE_STORE(i, v) covered_tile[i] = (v)
#endif

ivec2 covered_tile_grid() {
    return (ivec2(frame.viewport.xy) + COVERED_TILE_SIZE - 1) / COVERED_TILE_SIZE;
}

ivec2 classify_region_grid() {
    return (ivec2(frame.viewport.xy) + CLASSIFY_REGION_SIZE - 1) / CLASSIFY_REGION_SIZE;
}

// covered_tile[] index of the reflective regions' dispatch arguments, after both per-layer parts
// of `layers` layers; the flags follow at + 4, the list at + 4 + regions.
uint classify_regions_base(int layers) {
    ivec2 grid = covered_tile_grid();
    return uint(2 * layers * grid.x * grid.y);
}

// Layer-0 pixel `pixel`'s 32x32 region (rows of regions).
uint reflective_region(ivec2 pixel) {
    ivec2 region = pixel / CLASSIFY_REGION_SIZE;
    return uint(region.y * classify_region_grid().x + region.x);
}

// covered_tile[] index of region r's flag.
uint reflective_region_flag(uint r) { return classify_regions_base(int(frame.clip.z)) + 4u + r; }

// Appends region r to the list the classify pass dispatches over.
void append_reflective_region(uint r) {
    uint base = classify_regions_base(int(frame.clip.z));
    ivec2 regions = classify_region_grid();
    uint n = COVERED_TILE_ADD(base, 1u);
    COVERED_TILE_STORE(base + 4u + uint(regions.x * regions.y) + n, r);
}

// Flags the 32x32 region of layer-0 pixel `pixel` as holding a reflective surface: the first
// invocation to flag it lists it for the classify pass (the plain read spares the atomic once the
// region is flagged).
void flag_reflective_region(ivec2 pixel) {
    uint r = reflective_region(pixel);
    uint flag = reflective_region_flag(r);
    if (COVERED_TILE_LOAD(flag) == 0u && COVERED_TILE_EXCHANGE(flag, 1u) == 0u) append_reflective_region(r);
}

// The same flag without listing the region: a plain store, no atomic, for a pass that flags
// many samples per region and lists the flagged regions afterwards (list_reflective_region). An
// atomic in a shader costs llvmpipe every invocation that reaches it, even where no lane runs it.
void mark_reflective_region(ivec2 pixel) {
    uint flag = reflective_region_flag(reflective_region(pixel));
    // Read first: a flag already set is not written again (two threads writing one cache line
    // would pass it back and forth).
    if (COVERED_TILE_LOAD(flag) == 0u) COVERED_TILE_STORE(flag, 1u);
}

// Lists region r (rows of regions) where mark_reflective_region flagged it: one invocation per
// region, in a dispatch after the flagging one.
void list_reflective_region(uint r) {
    ivec2 regions = classify_region_grid();
    if (r < uint(regions.x * regions.y) && COVERED_TILE_LOAD(reflective_region_flag(r)) != 0u)
        append_reflective_region(r);
}
