#version 450 core
// Composite: the final image. Layer 0's lit colour where a surface covers the pixel, the
// environment seen through the pixel elsewhere.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/environment.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0) uniform sampler2DArray u_lit;
layout(binding = 1) uniform sampler2DArray u_material;

layout(binding = 0, rgba32f) writeonly uniform image2D o_color;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) return;
    vec3 c;
    if (texelFetch(u_material, ivec3(p, 0), 0).g > 0.5) {
        c = texelFetch(u_lit, ivec3(p, 0), 0).rgb;
    } else {
        vec3 dir_view = normalize(view_position(vec2(p) + 0.5, 1.0));
        c = environment_radiance(normalize(mat3(frame.inv_view) * dir_view));
    }
    imageStore(o_color, p, vec4(c, 1.0));
}
