// The resolve's work list (FidelityFX SSSR's tile classification, seed 000 4.1),
// written by the classify pass: the resolve then runs by indirect dispatch over what reflects
// only, and an empty list costs it no work (a dispatch of 0 groups). Two forms:
//   RESOLVE_LIST_PIXELS 1: one packed full-resolution pixel (x | y << 16) per receiving pixel
//                          (is_reflective), 64 entries per group: the own-rays resolve;
//   RESOLVE_LIST_PIXELS 0: one packed 16x16 tile (x | y << 16, in tiles) per tile holding a
//                          receiver, one group per tile: the tiled neighbour-reuse resolve. A
//                          tile's flag (entries[capacity + tile]) lets only its first receiver
//                          append it.
// Layout (std430): the header is 8 uints, then `capacity` entries, then the tile flags.
layout(std430, binding = BUFFER_RESOLVE_LIST) coherent buffer ResolveList {
    uint groups_x;           // glDispatchComputeIndirect, in rows of RESOLVE_LIST_ROW groups
    uint groups_y;           // (the dispatch's x count has a limit, 65535)
    uint groups_z;           // 1
    uint count;              // entries: receiving pixels, or tiles holding one
    uint environment_pixels; // reflective pixels rougher than the cutoff, given the environment
    uint capacity;           // entries the list holds (the tile flags follow them)
    uint pad0;
    uint pad1;
    uint entries[];
} resolve_list;

#ifndef RESOLVE_LIST_PIXELS
#define RESOLVE_LIST_PIXELS 0
#endif

const uint RESOLVE_LIST_ROW = 1024u;

uint resolve_list_pack(ivec2 v) { return uint(v.x) | (uint(v.y) << 16); }
ivec2 resolve_list_unpack(uint e) { return ivec2(int(e & 0xffffu), int(e >> 16)); }

// Reserves `n` consecutive entries (one atomic for several) and returns the first;
// entry i opens group i / per_group, and a group that starts a row adds the row.
uint resolve_list_reserve(uint n, uint per_group) {
    uint first = atomicAdd(resolve_list.count, n);
    for (uint i = first; i < first + n; ++i) {
        if (i % per_group != 0u) continue;
        uint g = i / per_group;
        atomicMax(resolve_list.groups_x, min(g + 1u, RESOLVE_LIST_ROW));
        if (g % RESOLVE_LIST_ROW == 0u) atomicAdd(resolve_list.groups_y, 1u);
    }
    return first;
}

// The classify pass's part for the tiles: full-resolution pixel `p` receives rays.
void resolve_list_add_tile_of(ivec2 p, int image_width) {
    ivec2 t = p / 16;
    uint flag = resolve_list.capacity + uint(t.y * ((image_width + 15) / 16) + t.x);
    // A plain read first: after the tile's first receiver, the others leave without an atomic.
    if (resolve_list.entries[flag] != 0u) return;
    if (atomicExchange(resolve_list.entries[flag], 1u) == 0u)
        resolve_list.entries[resolve_list_reserve(1u, 1u)] = resolve_list_pack(t);
}

// The resolve's part: the index of the entry (pixels) or the group's tile (tiles) it serves.
uint resolve_list_index() {
    uint group = gl_WorkGroupID.y * RESOLVE_LIST_ROW + gl_WorkGroupID.x;
#if RESOLVE_LIST_PIXELS
    return group * 64u + gl_LocalInvocationIndex;
#else
    return group;
#endif
}
