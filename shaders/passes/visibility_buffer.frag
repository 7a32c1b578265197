#version 450 core
// Subgroup ballots, where the device has them: the append takes one atomic per subgroup
// (lib/visibility_lists.glsl).
#extension GL_ARB_shader_ballot : enable
#extension GL_ARB_gpu_shader_int64 : enable
#if defined(GL_ARB_shader_ballot) && defined(GL_ARB_gpu_shader_int64)
#define VISIBILITY_BALLOT 1
#endif
// visibility_buffer: the geometry pass of the visibility constructions (passes/visibility_buffer.cpp),
// fragment stage. Burns and Hunt 2013's visibility buffer: the raster writes depth and the
// fragment's triangle only, and every attribute is rebuilt afterwards from the triangle and the
// pixel's ray (passes/gbuffer_attributes.comp), once per kept sample, by compute stores instead of
// the colour outputs of the raster pipeline.
// Variants:
//   VISIBILITY_APPEND 0: peeling (Everitt 2001, seed 000 2.2): writes the sample's id (lib/visibility.glsl) to a R32UI target
//     while the depth test keeps the nearest; PEEL_TEST 1 (layer i > 0) first discards every
//     fragment not behind layer i-1 (lib/layer_separation.glsl), as peeling's depth pass does.
//   VISIBILITY_APPEND 1: appends every fragment's (depth, triangle) to its pixel's list
//     (lib/visibility_lists.glsl); passes/visibility_select.comp keeps the nearest layers.
//   ALPHA_TEST 1: an alpha-tested material's holes are discarded, with the very test and texture
//     sample of peeling's depth pass, so both keep the same surfaces.
//   MARK_TILES 1 (Renderer.visibility_tiles, the layers after the first): every fragment kept marks
//     its 8x8 tile of layer u_layer in lib/visibility_tiles.glsl (a plain store of the same value):
//     the next layer rasterises the covered tiles' bounding box only and the attribute pass
//     classifies the covered tiles only.
#ifndef VISIBILITY_APPEND
#define VISIBILITY_APPEND 0
#endif
#ifndef PEEL_TEST
#define PEEL_TEST 0
#endif
#ifndef ALPHA_TEST
#define ALPHA_TEST 0
#endif
#ifndef MARK_TILES
#define MARK_TILES 0
#endif

#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/scene_data.glsl"

uniform int u_object;
uniform uint u_id_base;  // the draw's bits of the sample id (lib/visibility.glsl): u_object << primitive bits

#if ALPHA_TEST
#include "../lib/gbuffer.glsl"
#include "../lib/normal_mapping.glsl"
#include "../lib/material.glsl"
layout(binding = TEXTURE_MATERIAL_BASE_COLOR) uniform sampler2D u_base_color_texture;  // sRGB; alpha is linear
in VertexOut {
    vec3 view_position;
    vec3 view_normal;
    vec4 uv;  // both sets (texture_set)
    vec4 view_tangent;
    vec4 color;
} fs;
#endif

#if PEEL_TEST
#include "../lib/layer_separation.glsl"
layout(binding = TEXTURE_VISIBILITY_BUFFER_PREVIOUS_DEPTH) uniform sampler2D u_previous_layer_depth;  // depth of layer i-1
#endif

#if MARK_TILES
#include "../lib/visibility_tiles.glsl"
uniform int u_layer;
#endif

#if VISIBILITY_APPEND
#include "../lib/visibility_lists.glsl"
#else
layout(location = 0) out uint o_triangle;
#endif

void main() {
#if ALPHA_TEST
    MaterialData m = materials[objects[u_object].material.x];
    vec4 base_texel = sample_material_texture(u_base_color_texture, m, 0, fs.uv, dFdxFine(fs.uv), dFdyFine(fs.uv));
    if (material_alpha_hole(m, base_texel, fs.color.a)) discard;
#endif
#if PEEL_TEST
    float previous = texelFetch(u_previous_layer_depth, ivec2(gl_FragCoord.xy), 0).r;
    if (!behind_layer(gl_FragCoord.z, previous)) discard;
#endif
    uint triangle = u_id_base | uint(gl_PrimitiveID);
#if VISIBILITY_APPEND
    visibility_list_append(ivec2(gl_FragCoord.xy), gl_FragCoord.z, triangle);
#else
    o_triangle = triangle;
#endif
#if MARK_TILES
    mark_visibility_tile(ivec2(gl_FragCoord.xy), u_layer);
#endif
}
