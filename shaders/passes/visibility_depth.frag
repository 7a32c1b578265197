#version 450 core
// visibility_buffer depth write (deep_gbuffer "visibility_lists"): layer u_layer of gbuffer.depth
// from the depths the selection kept (passes/visibility_select.comp), written as the fragment
// depth of one full-screen triangle (passes/deep_gbuffer_write.vert) with the depth test ALWAYS:
// the stored window depth, bit for bit the one peeling's depth test keeps. Depth only: a depth
// target is no image a compute pass may store to.
#include "../lib/frame_uniforms.glsl"

layout(std430, binding = 25) readonly buffer VisibilityDepth { float visibility_depth[]; };

uniform int u_layer;

void main() {
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 p = ivec2(gl_FragCoord.xy);
    gl_FragDepth = visibility_depth[uint(u_layer) * uint(size.x * size.y) + uint(p.y * size.x + p.x)];
}
