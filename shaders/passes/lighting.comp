#version 450 core
// Lighting pass: shades every layer of the deep G-buffer (seed 000, 1.1.1 "lighting pass"),
// so that a reflection ray that hits layer k has a colour to fetch. Also writes each
// layer's linear view-space depth, which the tracers and the Python readback use.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/brdf.glsl"
#include "../lib/lights.glsl"
#include "../lib/shading.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler2DArray u_depth;
layout(binding = 1) uniform sampler2DArray u_albedo;
layout(binding = 2) uniform sampler2DArray u_normal;
layout(binding = 3) uniform sampler2DArray u_material;
layout(binding = 4) uniform sampler2DShadow u_shadow_map;

layout(binding = 0, rgba16f) writeonly uniform image2DArray o_lit;
layout(binding = 1, r32f) writeonly uniform image2DArray o_linear_depth;

#include "../lib/shadow_map.glsl"

void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID);
    if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) return;

    GSample g = gbuffer_decode(texelFetch(u_albedo, p, 0), texelFetch(u_normal, p, 0), texelFetch(u_material, p, 0));
    if (!g.covered) {
        imageStore(o_linear_depth, p, vec4(frame.clip.y));  // nothing here: exactly the far plane
        imageStore(o_lit, p, vec4(0.0));
        return;
    }
    float z = linear_depth(texelFetch(u_depth, p, 0).r);
    imageStore(o_linear_depth, p, vec4(z));
    vec3 pos = view_position(vec2(p.xy) + 0.5, z);
    vec3 radiance = shade_surface(g, pos, normalize(-pos));
    imageStore(o_lit, p, vec4(radiance, 1.0));
}
