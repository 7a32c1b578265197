// Per-pixel lists of visibility samples, the geometry pass of deep_gbuffer "visibility_lists"
// (passes/visibility_buffer.cpp): Yang, Hensley, Grün and Thibieroz 2010's concurrent linked
// lists, storing only what visibility needs (Burns and Hunt 2013): a fragment's window depth and
// its triangle (lib/visibility.glsl), 8 bytes, and its link, 4 bytes. Every attribute is rebuilt
// later from the kept triangles (passes/gbuffer_attributes.comp), so a fragment costs 12 bytes
// where the shaded lists (lib/fragment_lists.glsl) store 64. A slot beyond the store's capacity
// is counted but not written: the pass reads the counter and redoes the geometry pass with a
// store that fits, or peels, so a list is never silently truncated.
#define VISIBILITY_LIST_END 0xffffffffu

layout(std430, binding = BUFFER_VISIBILITY_FRAGMENTS) buffer VisibilityFragments { uvec2 visibility_fragment[]; };  // (depth bits, triangle)
layout(std430, binding = BUFFER_VISIBILITY_LINKS) buffer VisibilityLinks { uint visibility_next[]; };
layout(std430, binding = BUFFER_VISIBILITY_HEADS) coherent buffer VisibilityHeads { uint visibility_head[]; };
// x: fragments appended (may exceed the capacity), y: the capacity, z: the most layers any pixel
// holds (the selection's maximum), w: unused.
layout(std430, binding = BUFFER_VISIBILITY_COUNTER) coherent buffer VisibilityCounter { uvec4 visibility_counter; };
// The store's capacity in fragments (visibility_counter.y), a uniform for the appending draw: a
// storage-buffer read per fragment costs the CPU device a loop over the lanes.
uniform uint u_list_capacity;

// This fragment's slot in the store. With subgroup ballots (VISIBILITY_BALLOT, defined by the
// including shader where it enabled them) the subgroup's fragments take consecutive slots by one
// atomic on the shared counter, where one atomic a fragment would pass the counter's cache line
// from thread to thread (the CPU device) and serialise the subgroup (a GPU). Helper invocations
// (whose atomics and stores do nothing) take no slot.
uint visibility_list_slot() {
#ifdef VISIBILITY_BALLOT
    uvec2 writers = unpackUint2x32(ballotARB(!gl_HelperInvocation));
    uvec2 before = writers & unpackUint2x32(gl_SubGroupLtMaskARB);
    uint rank = uint(bitCount(before.x) + bitCount(before.y));
    // The lowest writing invocation takes the subgroup's slots and hands out the first.
    int leader = writers.x != 0u ? findLSB(writers.x) : 32 + findLSB(writers.y);
    uint first = 0u;
    if (int(gl_SubGroupInvocationARB) == leader)
        first = atomicAdd(visibility_counter.x, uint(bitCount(writers.x) + bitCount(writers.y)));
    return readInvocationARB(first, uint(leader)) + rank;
#else
    return atomicAdd(visibility_counter.x, 1u);
#endif
}

void visibility_list_append(ivec2 pixel, float depth, uint triangle) {
    uint slot = visibility_list_slot();
    if (slot >= u_list_capacity) return;
    visibility_fragment[slot] = uvec2(floatBitsToUint(depth), triangle);
    visibility_next[slot] = atomicExchange(visibility_head[pixel.y * int(frame.viewport.x) + pixel.x], slot);
}
