#version 450 core
// composite: the final image. Where a surface covers the pixel, its lit colour c_d, blended
// with its reflection c_r when there is one:
//   linear (seed 000, 2.4.2): c = r c_r + (1 - r) c_d
//   pbr:                      c = c_d + k E c_r
// with r the surface's reflectivity; the environment where no surface covers the pixel.
// In the pbr composite, c_r is the lobe-weighted mean radiance the resolve returns (its weights
// are normalised), so the split-sum approximation (Karis 2013) turns it into reflected
// radiance with the GGX directional albedo E = F0 A(n.v, roughness) + B(n.v, roughness)
// (lib/specular_albedo.glsl): a rough surface reflects less than F(n.v) says. k is the
// thesis's reflectivity r as a scale, or 1 for a material that reflects as its
// metallic-roughness parameters say ("auto"), whose G-buffer r is the luminance of E itself.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/environment.glsl"
#include "../lib/input_fetch.glsl"
#if REFLECTIONS
#include "../lib/ssr_settings.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/brdf.glsl"
#include "../lib/scene_data.glsl"
#include "../lib/specular_albedo.glsl"
#include "../lib/gbuffer_specular.glsl"
#endif

#ifndef LIT_CARRIES_R
#define LIT_CARRIES_R 0  // 1: u_lit is the lighting pass's "lit", whose alpha holds coverage and r
#endif
#ifndef PBR_COMPOSITE
#define PBR_COMPOSITE 0  // 1: c = c_d + k E c_r (Settings.composite "pbr"); set by passes/composite.cpp
#endif

layout(local_size_x = 8, local_size_y = 8) in;

// By name ("direct", "reflection", "output": passes/composite.cpp); with FETCH_BY_IMAGE the float
// inputs are images (composite.cpp gives the formats that depend on the chain).
#ifndef DIRECT_FORMAT
#define DIRECT_FORMAT rgba16f
#endif
#ifndef REFLECTION_FORMAT
#define REFLECTION_FORMAT rgba16f
#endif
INPUT_ARRAY(u_lit, TEXTURE_DIRECT, IMAGE_DIRECT, DIRECT_FORMAT);
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;
#if REFLECTIONS
INPUT_2D(u_reflection, TEXTURE_REFLECTION, IMAGE_REFLECTION, REFLECTION_FORMAT);
layout(binding = TEXTURE_GBUFFER_ALBEDO) uniform sampler2DArray u_albedo;
INPUT_ARRAY(u_normal, TEXTURE_GBUFFER_NORMAL, IMAGE_GBUFFER_NORMAL, rgba16f);
INPUT_ARRAY(u_linear_depth, TEXTURE_LINEAR_DEPTH, IMAGE_LINEAR_DEPTH, r32f);
layout(binding = TEXTURE_SPECULAR_ALBEDO) uniform sampler2D u_specular_albedo;
#endif

layout(binding = IMAGE_OUTPUT, rgba32f) writeonly uniform image2D o_color;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) return;
    vec4 lit = FETCH(u_lit, ivec3(p, 0));
#if LIT_CARRIES_R
    // Coverage and r come with the lit colour (lit.a = 0.5 + r / 2 where covered, 0
    // where not; passes/lighting.comp), one fetch instead of two. r is the G-buffer's RGBA8
    // value k / 255, which the half float keeps to 2.5e-4, so rounding to k / 255 recovers it.
    bool covered = lit.a > 0.25;
    float r = round((2.0 * lit.a - 1.0) * 255.0) / 255.0;
#else
    vec4 m = texelFetch(u_material, ivec3(p, 0), 0);
    bool covered = m.g > 0.5;
    float r = m.r;
#endif
    vec3 c;
    if (covered) {
        c = lit.rgb;
#if REFLECTIONS
        if (r > 0.0) {
            vec3 reflection = FETCH(u_reflection, p).rgb;
#if !PBR_COMPOSITE
            c = r * reflection + (1.0 - r) * c;
#else
            {
                GSample g = gbuffer_decode(texelFetch(u_albedo, ivec3(p, 0), 0), FETCH(u_normal, ivec3(p, 0)),
                                           texelFetch(u_material, ivec3(p, 0), 0));
                vec3 pos = view_position(vec2(p) + 0.5, FETCH(u_linear_depth, ivec3(p, 0)).r);
                float NoV = max(dot(g.normal, normalize(-pos)), 0.0);
                vec2 ab = texture(u_specular_albedo, specular_albedo_uv(NoV, g.roughness)).rg;
                bool auto_r = g.object_id >= 0 && materials[objects[g.object_id].material.x].params.z < 0.0;
                c += (auto_r ? 1.0 : r) * specular_albedo(mix(gbuffer_dielectric_f0(ivec3(p, 0), g), g.albedo, g.metallic), ab) * reflection;
            }
#endif
        }
#endif
    } else {
        c = environment_radiance_view(view_position(vec2(p) + 0.5, 1.0));
    }
    imageStore(o_color, p, vec4(c, 1.0));
}
