// The visibility buffer's sample (Burns and Hunt 2013, "The Visibility Buffer: A Cache-Friendly
// Approach to Deferred Shading"): one 32-bit id per kept fragment naming its triangle, the draw
// (GpuScene::draws(): draw i is object i) in the high bits and gl_PrimitiveID within it in the low
// u_primitive_bits bits (passes/visibility_buffer.h, VisibilityBufferPass::primitive_bits: as few
// as the scene's largest mesh needs). Decoding is arithmetic, without a table to search.
#define VISIBILITY_NONE 0xffffffffu

uniform int u_primitive_bits;

int visibility_object(uint id) { return int(id >> uint(u_primitive_bits)); }
int visibility_primitive(uint id) { return int(id & ((1u << uint(u_primitive_bits)) - 1u)); }

// Of two fragments at exactly the same depth, whether id a is the one depth peeling's shading
// pass leaves in the G-buffer (passes/depth_peel.cpp: it draws the draws in reverse order and each
// draw's triangles in order, so the lowest draw wins, and within it the last triangle).
// With the primitive's bits flipped, that order is the ids' order as unsigned integers: a lower
// object, or within one the higher primitive, gives the lower key.
bool visibility_wins(uint a, uint b) {
    uint primitive_bits = (1u << uint(u_primitive_bits)) - 1u;
    return (a ^ primitive_bits) < (b ^ primitive_bits);
}

// A sample of the deep G-buffer, as a work list names it: its texel packed into 32 bits, the layer
// in the top 4 (at most 16 layers), then the row and the column in 14 bits each (images up to
// 16384 on a side, the renderer's limit). Shifts and masks decode it, where an index
// layer * width * height + pixel takes integer divisions, which the CPU device runs lane by lane.
uint sample_index(ivec2 p, int layer) {
    return uint(layer) << 28 | uint(p.y) << 14 | uint(p.x);
}
ivec3 sample_texel(uint s) {
    return ivec3(int(s & 0x3fffu), int((s >> 14) & 0x3fffu), int(s >> 28));
}
