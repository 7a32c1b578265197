#version 450 core
// Geometry pass with depth peeling (seed 000, 1.5.1 and 2.2): fragment stage.
// Layer 0 is the ordinary G-buffer; layer i > 0 keeps only fragments strictly behind
// layer i-1 at the same pixel (Everitt 2001; with Settings.min_separation also that far behind
// it, lib/layer_separation.glsl), and the depth test keeps the nearest of them.
// Two variants (passes/depth_peel.cpp): PEEL_DEPTH_ONLY 1 is the depth pass, which
// only peels (PEEL_TEST: layer i > 0) and writes the layer's depth; PEEL_DEPTH_ONLY 0 shades
// the G-buffer afterwards with the depth test EQUAL and early fragment tests, so the material
// is evaluated once per pixel instead of for every fragment the peel or the depth test rejects
// after shading (a shader that may discard gets only late depth writes).
#ifndef PEEL_DEPTH_ONLY
#define PEEL_DEPTH_ONLY 0
#endif
#ifndef PEEL_TEST
#define PEEL_TEST 0
#endif
// PEEL_ALPHA_TEST 1: the depth pass of an alpha-tested material (glTF MASK/BLEND) discards the
// texels the shading pass would, so the depth it keeps is the surface seen through the holes
// (the shading pass, with GL_EQUAL and early tests, cannot discard what the depth already hides).
#ifndef PEEL_ALPHA_TEST
#define PEEL_ALPHA_TEST 0
#endif
// The shading pass is compiled per material kind (GpuScene::material_features), as
// llvmpipe runs the texture samples of a branch no lane takes: MATERIAL_TEXTURES has a bit per
// texture slot the material has (1 base colour, 2 metallic-roughness, 4 normal, 8 emissive,
// 16 specular, 32 specular colour; 0: none), MATERIAL_AUTO_R 0 for an explicit reflectivity.
// An absent slot reads white without a sample, what GpuScene binds there: the same values.
#ifndef MATERIAL_TEXTURES
#define MATERIAL_TEXTURES 63
#endif
// The one-pass deep G-buffer (per-pixel fragment lists, Yang et al. 2010): DEEP_GBUFFER_APPEND 1
// runs this same shading code for every fragment, without a depth test, and appends the encoded
// outputs to the pixel's list (lib/fragment_lists.glsl) instead of writing them; the selection
// and write passes (passes/deep_gbuffer_*.{comp,frag}) later write the kept ones through the same
// framebuffer formats, so the layers equal peeling's bit for bit.
#ifndef DEEP_GBUFFER_APPEND
#define DEEP_GBUFFER_APPEND 0
#endif
// EMISSION_TEXTURE 1 (a scene with an emissive texture, FrameFacts::emission_texture): the
// shading pass also writes the surface's emitted radiance (gbuffer.emission), sampled here where
// the texture coordinates are; the lighting pass, which has none, reads it.
#ifndef EMISSION_TEXTURE
#define EMISSION_TEXTURE 0
#endif
// MOTION_VECTORS 1 (Settings.motion_vectors): the shading pass also writes gbuffer.motion, the
// output after gbuffer.specular's place (lib/motion.glsl).
// SPECULAR_TEXTURE 1 (a scene with a KHR_materials_specular texture, FrameFacts::specular_texture):
// the shading pass also writes every surface's dielectric F0 (gbuffer.specular, the output after
// gbuffer.emission's place), sampled here; the passes that take F0 from the G-buffer read it.
#ifndef SPECULAR_TEXTURE
#define SPECULAR_TEXTURE 0
#endif

// (the shader library includes a file once: includes both variants use come first)
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/scene_data.glsl"

#if PEEL_DEPTH_ONLY
#include "../lib/layer_separation.glsl"

layout(binding = TEXTURE_DEPTH_PEEL_PREVIOUS_DEPTH) uniform sampler2D u_previous_layer_depth;  // depth of layer i-1

#if PEEL_ALPHA_TEST
layout(binding = TEXTURE_MATERIAL_BASE_COLOR) uniform sampler2D u_base_color_texture;  // sRGB; alpha is linear
uniform int u_object;
in VertexOut {
    vec3 view_position;
    vec3 view_normal;
    vec4 uv;  // both sets (texture_set)
    vec4 view_tangent;
    vec4 color;
} fs;
#endif

void main() {
#if PEEL_ALPHA_TEST
    // The same test as material_alpha_hole (lib/material.glsl), on the same texture sample.
    MaterialData m = materials[objects[u_object].material.x];
    vec4 base_texel = sample_material_texture(u_base_color_texture, m, 0, fs.uv, dFdxFine(fs.uv), dFdyFine(fs.uv));
    float alpha = m.base_color.a * (m.flags.x != 0 ? base_texel.a : 1.0) * fs.color.a;
    if (m.emissive.w >= 0.0 && alpha < m.emissive.w) discard;
#endif
#if PEEL_TEST
    float previous = texelFetch(u_previous_layer_depth, ivec2(gl_FragCoord.xy), 0).r;
    if (!behind_layer(gl_FragCoord.z, previous)) discard;
#endif
}
#else
#if DEEP_GBUFFER_APPEND
#include "../lib/fragment_lists.glsl"
uniform int u_draw;  // the draw's index in GpuScene::draws(): the tie rule of equal depths
#else
// Only fragments at the depth the depth pass kept reach the shader.
layout(early_fragment_tests) in;
#endif
#include "../lib/scene_data.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/normal_mapping.glsl"
#include "../lib/material.glsl"
#include "../lib/brdf.glsl"
#include "../lib/specular_albedo.glsl"
#include "../lib/covered_tiles.glsl"

layout(binding = TEXTURE_MATERIAL_BASE_COLOR) uniform sampler2D u_base_color_texture;          // sRGB
layout(binding = TEXTURE_MATERIAL_METALLIC_ROUGHNESS) uniform sampler2D u_metallic_roughness_texture;  // G roughness, B metallic
layout(binding = TEXTURE_MATERIAL_NORMAL_MAP) uniform sampler2D u_normal_texture;              // tangent space
#if EMISSION_TEXTURE && MATERIAL_TEXTURES
// (declared only where bound: its unit may hold another pass's shadow map, a comparison sampler)
layout(binding = TEXTURE_MATERIAL_EMISSIVE) uniform sampler2D u_emissive_texture;  // sRGB
#endif
#if SPECULAR_TEXTURE && MATERIAL_TEXTURES
layout(binding = TEXTURE_MATERIAL_SPECULAR) uniform sampler2D u_specular_texture;        // A
layout(binding = TEXTURE_MATERIAL_SPECULAR_COLOR) uniform sampler2D u_specular_color_texture;  // sRGB
#endif
layout(binding = TEXTURE_SPECULAR_ALBEDO) uniform sampler2D u_specular_albedo;  // (A, B) split-sum table

uniform int u_object;
uniform int u_layer;

in VertexOut {
    vec3 view_position;
    vec3 view_normal;
    vec4 uv;  // both sets (texture_set)
    vec4 view_tangent;
    vec4 color;
} fs;

#ifndef MOTION_VECTORS
#define MOTION_VECTORS 0
#endif
#if MOTION_VECTORS
#include "../lib/motion.glsl"
in vec4 vs_motion_clip;
in vec4 vs_motion_previous_clip;
flat in int vs_motion_still;
#endif

#if !DEEP_GBUFFER_APPEND
layout(location = 0) out vec4 o_albedo_metallic;
layout(location = 1) out vec4 o_normal_roughness;
layout(location = 2) out vec4 o_material;
#if EMISSION_TEXTURE
layout(location = 3) out vec4 o_emission;
#endif
#if SPECULAR_TEXTURE
layout(location = 3 + EMISSION_TEXTURE) out vec4 o_specular;
#endif
#if MOTION_VECTORS
layout(location = 3 + EMISSION_TEXTURE + SPECULAR_TEXTURE) out vec4 o_motion;  // gbuffer.motion (RG32F)
#endif
#endif

#include "../lib/gbuffer_shading.glsl"

void main() {
    GBufferSurface surface;
    surface.view_position = fs.view_position;
    surface.view_normal = fs.view_normal;
    surface.uv = fs.uv;
    surface.view_tangent = fs.view_tangent;
    surface.color = fs.color;
#if MATERIAL_TEXTURES
    // Fine derivatives (GLSL 4.50): along the fragment's own row and column on every device, where
    // plain dFdx may take the quad's coarse one; the visibility constructions' attribute pass takes
    // the same differences from its rays (passes/gbuffer_attributes.comp).
    surface.duv_dx = dFdxFine(fs.uv);
    surface.duv_dy = dFdyFine(fs.uv);
    surface.dpos_dx = dFdxFine(fs.view_position);
    surface.dpos_dy = dFdyFine(fs.view_position);
#else
    surface.duv_dx = surface.duv_dy = vec4(0.0);
    surface.dpos_dx = surface.dpos_dy = vec3(0.0);
#endif
    surface.front_facing = gl_FrontFacing;
    surface.object = u_object;
    GBufferTexel texel = gbuffer_shade(surface, materials[objects[u_object].material.x]);
    // A hole of an alpha-tested material: the lists must not append it (peeling's depth pass
    // already discarded it, so here it only guards against a coplanar surface's equal depth).
    if (texel.hole) discard;
    GSample g = texel.g;
    vec4 emission_out = texel.emission, specular_out = texel.specular;
#if MOTION_VECTORS
    vec4 motion_out = vs_motion_still != 0 ? vec4(0.0) : motion_texel(vs_motion_clip, vs_motion_previous_clip);
#else
    vec4 motion_out = vec4(0.0);
#endif
#if DEEP_GBUFFER_APPEND
    vec4 albedo_metallic, normal_roughness, material;
    gbuffer_encode(g, albedo_metallic, normal_roughness, material);
    fragment_list_append(ivec2(gl_FragCoord.xy), gl_FragCoord.z, albedo_metallic, normal_roughness, material,
                         emission_out, specular_out, motion_out, uint(u_draw), uint(gl_PrimitiveID),
                         g.reflectivity > 0.0);
#else
    gbuffer_encode(g, o_albedo_metallic, o_normal_roughness, o_material);
#if EMISSION_TEXTURE
    o_emission = emission_out;
#endif
#if SPECULAR_TEXTURE
    o_specular = specular_out;
#endif
#if MOTION_VECTORS
    o_motion = motion_out;
#endif
    // This layer's tile holds a surface (every fragment of it stores the same value).
    ivec2 grid = covered_tile_grid();
    ivec2 tile = ivec2(gl_FragCoord.xy) / COVERED_TILE_SIZE;
    covered_tile[(u_layer * grid.y + tile.y) * grid.x + tile.x] = 1u;
    if (u_layer == 0 && g.reflectivity > 0.0) flag_reflective_region(ivec2(gl_FragCoord.xy));
#endif
}
#endif
