// The ray list of the classify pass (FidelityFX SSSR's tile classification, seed 000
// 4.1): the trace pixels that need rays, compacted by an atomic counter, with the indirect
// dispatch arguments of the trace pass in the same buffer so that an empty list costs no
// trace work at all (a dispatch of 0 groups). The counters are read back for Frame.stats; the
// trace's own two (rays_traced, fetches) are kept by the variance-guided second trace only
// (extra_rays, extra_depth_fetches): the first trace's are summed from rays.sample on demand.
// Layout (std430): the header is 8 uints, then one packed pixel (x | y << 16) per entry.
layout(std430, binding = BUFFER_RAY_LIST) coherent buffer RayList {
    uint groups_x;      // glDispatchComputeIndirect: groups of 8x8 invocations, 64 entries each, in
    uint groups_y;      // rows of RAY_LIST_ROW groups (the dispatch's x count has a limit, 65535)
    uint groups_z;      // the rays each pixel traces (Settings.traced_rays)
    uint count;         // trace pixels in the list
    uint rays_traced;   // EXTRA_RAYS: rays the second trace generated (weight > 0)
    uint fetches;       // EXTRA_RAYS: depth fetches the second trace spent, summed
    uint classified;    // trace pixels the classify pass examined
    uint listed_pixels; // RAY_LIST_PER_RAY: trace pixels in the list (count is then rays)
    uint pixels[];      // one packed pixel per entry; RAY_LIST_PER_RAY: (packed pixel, ray) pairs
} ray_list;

//, adaptive rays over the list: one entry per (pixel, ray) the pixel traces, so the
// trace's invocations follow the rays traced, not rays_per_pixel slots per pixel (groups_z = 1).
#ifndef RAY_LIST_PER_RAY
#define RAY_LIST_PER_RAY 0
#endif

const uint RAY_LIST_ROW = 1024u;

// Classify's share of the dispatch arguments: entry i opens group i / 64, and each group that
// starts a row adds the row.
void ray_list_open_group(uint i) {
    if (i % 64u != 0u) return;
    uint g = i / 64u;
    atomicMax(ray_list.groups_x, min(g + 1u, RAY_LIST_ROW));
    if (g % RAY_LIST_ROW == 0u) atomicAdd(ray_list.groups_y, 1u);
}

uint pack_pixel(ivec2 q) { return uint(q.x) | (uint(q.y) << 16); }
ivec2 unpack_pixel(uint entry) { return ivec2(int(entry & 0xffffu), int(entry >> 16)); }

// List entry `index`: its trace pixel and ray (per-ray lists hold the ray, pixel lists take it
// from gl_WorkGroupID.z); false past the list's end.
bool ray_list_entry_at(uint index, out ivec3 id) {
    id = ivec3(0);
    if (index >= ray_list.count) return false;
#if RAY_LIST_PER_RAY
    id = ivec3(unpack_pixel(ray_list.pixels[2u * index]), int(ray_list.pixels[2u * index + 1u]));
#else
    id = ivec3(unpack_pixel(ray_list.pixels[index]), int(gl_WorkGroupID.z));
#endif
    return true;
}

// The trace pass's invocation of the list entry it serves (8x8 groups, one list entry per
// invocation, gl_WorkGroupID.z = the ray).
bool ray_list_entry(out ivec3 id) {
    return ray_list_entry_at((gl_WorkGroupID.y * RAY_LIST_ROW + gl_WorkGroupID.x) * 64u + gl_LocalInvocationIndex, id);
}

// Frame.stats of the variance-guided second trace: rays it generated and the depth fetches they spent.
void ray_list_add(uint rays, uint fetches) {
    if (rays == 0u) return;
    atomicAdd(ray_list.rays_traced, rays);
    atomicAdd(ray_list.fetches, fetches);
}

// The same for one ray (weight 0: no ray).
void ray_list_count(float weight, float fetches) {
    ray_list_add(weight > 0.0 ? 1u : 0u, uint(fetches));
}
