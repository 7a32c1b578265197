// Per-pixel lists of visibility samples, the geometry pass of deep_gbuffer "visibility_lists"
// (passes/visibility_buffer.cpp): Yang, Hensley, Grün and Thibieroz 2010's concurrent linked
// lists, storing only what visibility needs (Burns and Hunt 2013): a fragment's window depth and
// its triangle (lib/visibility.glsl), 8 bytes, and its link, 4 bytes. Every attribute is rebuilt
// later from the kept triangles (passes/gbuffer_attributes.comp), so a fragment costs 12 bytes
// where the shaded lists (lib/fragment_lists.glsl) store 64. A slot beyond the store's capacity
// is counted but not written: the pass reads the counter and redoes the geometry pass with a
// store that fits, or peels, so a list is never silently truncated.
#define VISIBILITY_LIST_END 0xffffffffu

layout(std430, binding = 21) buffer VisibilityFragments { uvec2 visibility_fragment[]; };  // (depth bits, triangle)
layout(std430, binding = 22) buffer VisibilityLinks { uint visibility_next[]; };
layout(std430, binding = 23) coherent buffer VisibilityHeads { uint visibility_head[]; };
// x: fragments appended (may exceed the capacity), y: the capacity, z: the most layers any pixel
// holds (the selection's maximum), w: unused.
layout(std430, binding = 24) coherent buffer VisibilityCounter { uvec4 visibility_counter; };
// The store's capacity in fragments (visibility_counter.y), a uniform for the appending draw: a
// storage-buffer read per fragment costs the CPU device a loop over the lanes.
uniform uint u_list_capacity;

void visibility_list_append(ivec2 pixel, float depth, uint triangle) {
    uint slot = atomicAdd(visibility_counter.x, 1u);
    if (slot >= u_list_capacity) return;
    visibility_fragment[slot] = uvec2(floatBitsToUint(depth), triangle);
    visibility_next[slot] = atomicExchange(visibility_head[pixel.y * int(frame.viewport.x) + pixel.x], slot);
}
