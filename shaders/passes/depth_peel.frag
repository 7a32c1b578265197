#version 450 core
// Geometry pass with depth peeling (seed 000, 1.5.1 and 2.2): fragment stage.
// Layer 0 is the ordinary G-buffer; layer i > 0 keeps only fragments strictly behind
// layer i-1 at the same pixel (Everitt 2001), and the depth test keeps the nearest of them.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/scene_data.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/normal_mapping.glsl"
#include "../lib/material.glsl"
#include "../lib/brdf.glsl"
#include "../lib/specular_albedo.glsl"

layout(binding = 0) uniform sampler2D u_base_color_texture;          // sRGB
layout(binding = 1) uniform sampler2D u_metallic_roughness_texture;  // G roughness, B metallic
layout(binding = 2) uniform sampler2D u_normal_texture;              // tangent space
layout(binding = 3) uniform sampler2D u_previous_layer_depth;        // depth of layer i-1
layout(binding = SPECULAR_ALBEDO_UNIT) uniform sampler2D u_specular_albedo;  // (A, B) split-sum table

uniform int u_object;
uniform int u_layer;

in VertexOut {
    vec3 view_position;
    vec3 view_normal;
    vec2 uv;
    vec4 view_tangent;
} fs;

layout(location = 0) out vec4 o_albedo_metallic;
layout(location = 1) out vec4 o_normal_roughness;
layout(location = 2) out vec4 o_material;

void main() {
    if (u_layer > 0) {
        float previous = texelFetch(u_previous_layer_depth, ivec2(gl_FragCoord.xy), 0).r;
        if (!is_farther(gl_FragCoord.z, previous)) discard;
    }

    MaterialData m = materials[objects[u_object].material.x];
    vec3 n = normalize(fs.view_normal);
    vec3 t, b;
    bool has_frame = false;
    if (m.flags.z != 0) {
        has_frame = tangent_frame_from_vertex(n, fs.view_tangent, t, b) ||
                    tangent_frame_from_gradients(n, dFdx(fs.view_position), dFdy(fs.view_position), dFdx(fs.uv),
                                                 dFdy(fs.uv), t, b);
    }
    GSample g = material_sample(m, texture(u_base_color_texture, fs.uv), texture(u_metallic_roughness_texture, fs.uv),
                                texture(u_normal_texture, fs.uv).xyz, n, t, b, has_frame, gl_FrontFacing, u_object);
    if (m.params.z < 0.0) {
        // A material without the thesis's explicit r (glTF files from other tools): it reflects
        // the share of light its GGX lobe does at this view angle, E = F0 A + B.
        float NoV = max(dot(g.normal, normalize(-fs.view_position)), 0.0);
        vec2 ab = texture(u_specular_albedo, specular_albedo_uv(NoV, g.roughness)).rg;
        g.reflectivity = specular_reflectivity(specular_f0(g.albedo, g.metallic), ab);
    }
    gbuffer_encode(g, o_albedo_metallic, o_normal_roughness, o_material);
}
