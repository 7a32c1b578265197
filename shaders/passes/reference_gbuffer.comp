#version 450 core
// The converged reference's G-buffer for the CPU tracer (cpp/passes/reference_cpu.h): every
// pixel's layer-0 sample decoded by lib/gbuffer.glsl itself and its linear depth, three vec4
// per pixel, so that the C++ port starts from the very values the GLSL reference decodes; with
// EMISSION_TEXTURE, every pixel's gbuffer.emission after them (one vec4 per pixel).
#include "../lib/frame_uniforms.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/scene_data.glsl"
#include "../lib/gbuffer_emission.glsl"
#include "../lib/gbuffer_specular.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = TEXTURE_LINEAR_DEPTH) uniform sampler2DArray u_linear_depth;
layout(binding = TEXTURE_GBUFFER_ALBEDO) uniform sampler2DArray u_albedo;
layout(binding = TEXTURE_GBUFFER_NORMAL) uniform sampler2DArray u_normal;
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;

layout(std430, binding = BUFFER_DECODED) writeonly buffer Decoded { vec4 decoded[]; };

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, ivec2(frame.viewport.xy)))) return;
    GSample g = gbuffer_decode(texelFetch(u_albedo, ivec3(p, 0), 0), texelFetch(u_normal, ivec3(p, 0), 0),
                               texelFetch(u_material, ivec3(p, 0), 0));
    int i = 3 * (p.y * int(frame.viewport.x) + p.x);
    decoded[i] = vec4(g.albedo, g.metallic);
    decoded[i + 1] = vec4(g.normal, g.roughness);
    decoded[i + 2] = vec4(g.reflectivity, g.covered ? 1.0 : 0.0, float(g.object_id),
                          texelFetch(u_linear_depth, ivec3(p, 0), 0).r);
#if EMISSION_TEXTURE
    int pixels = int(frame.viewport.x) * int(frame.viewport.y);
    decoded[3 * pixels + p.y * int(frame.viewport.x) + p.x] = vec4(gbuffer_emission(ivec3(p, 0), g), 1.0);
#endif
#if SPECULAR_TEXTURE
    // ... and every pixel's gbuffer.specular after those (one vec4 per pixel).
    int at = (3 + EMISSION_TEXTURE) * int(frame.viewport.x) * int(frame.viewport.y);
    decoded[at + p.y * int(frame.viewport.x) + p.x] = vec4(gbuffer_dielectric_f0(ivec3(p, 0), g), 1.0);
#endif
}
