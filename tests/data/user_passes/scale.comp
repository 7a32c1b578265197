#version 450 core
// A placed pass of the tests: multiplies the texture it rewrites by u_gain (colour and alpha), so
// that its output is known from the frame without it. Reads[0] is the copy of the rewritten texture
// taken before it runs; writes[0] at image unit 0 (reflection, rgba16f).
#include "lib/frame_uniforms.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D u_source;
layout(rgba16f, binding = 0) writeonly uniform image2D o_target;

uniform float u_gain;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, ivec2(frame.viewport.xy)))) return;
    imageStore(o_target, p, u_gain * texelFetch(u_source, p, 0));
}
