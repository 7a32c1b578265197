#version 450 core
// scale.comp for an rgba32f texture (reflection.denoised, reflection.temporal): multiplies it by u_gain.
#include "lib/frame_uniforms.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D u_source;
layout(rgba32f, binding = 0) writeonly uniform image2D o_target;

uniform float u_gain;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, ivec2(frame.viewport.xy)))) return;
    imageStore(o_target, p, u_gain * texelFetch(u_source, p, 0));
}
