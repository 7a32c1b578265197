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

// A sample of the deep G-buffer, as a work list names it: layer * width * height + pixel (rows).
// Needs frame_uniforms.
uint sample_index(ivec2 p, int layer) {
    ivec2 size = ivec2(frame.viewport.xy);
    return uint(layer) * uint(size.x * size.y) + uint(p.y * size.x + p.x);
}
ivec3 sample_texel(uint s) {
    uint plane = uint(frame.viewport.x) * uint(frame.viewport.y);
    uint pixel = s % plane;
    return ivec3(int(pixel % uint(frame.viewport.x)), int(pixel / uint(frame.viewport.x)), int(s / plane));
}
