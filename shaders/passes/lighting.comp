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

#if SHADOWS
float shadow_visibility(vec3 p_view, vec3 n_view) {
    // Normal offset (in world units: texel size x offset in texels) against acne.
    vec3 p = p_view + n_view * (frame.shadow.y * frame.shadow.z);
    vec3 s = (frame.view_to_shadow * vec4(p, 1.0)).xyz;
    if (any(lessThan(s, vec3(0.0))) || any(greaterThan(s, vec3(1.0)))) return 1.0;
    int r = int(frame.shadow.w);
    vec2 texel = 1.0 / vec2(textureSize(u_shadow_map, 0));
    float lit = 0.0;
    for (int y = -r; y <= r; ++y)
        for (int x = -r; x <= r; ++x)
            lit += texture(u_shadow_map, vec3(s.xy + vec2(x, y) * texel, s.z));
    return lit / float((2 * r + 1) * (2 * r + 1));
}
#else
float shadow_visibility(vec3 p_view, vec3 n_view) { return 1.0; }
#endif

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
