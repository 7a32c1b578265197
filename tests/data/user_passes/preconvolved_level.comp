#version 450 core
// A glossy filter on the pre-convolved mips: the reflection of a pixel becomes the pre-convolved
// lit colour of its nearest surface at mip level u_level (the texel over it), alpha 1. Reads[0]
// lit_preconvolved (a 2D array with its mip chain), writes[0] reflection at image unit 0.
#include "lib/frame_uniforms.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2DArray u_preconvolved;
layout(rgba16f, binding = 0) writeonly uniform image2D o_reflection;

uniform int u_level;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, ivec2(frame.viewport.xy)))) return;
    vec3 c = texelFetch(u_preconvolved, ivec3(p >> u_level, 0), u_level).rgb;
    imageStore(o_reflection, p, vec4(c, 1.0));
}
