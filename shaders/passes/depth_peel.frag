#version 450 core
// Geometry pass with depth peeling (seed 000, 1.5.1 and 2.2): fragment stage.
// Layer 0 is the ordinary G-buffer; layer i > 0 keeps only fragments strictly behind
// layer i-1 at the same pixel (Everitt 2001), and the depth test keeps the nearest of them.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/scene_data.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/normal_mapping.glsl"

layout(binding = 0) uniform sampler2D u_base_color_texture;          // sRGB
layout(binding = 1) uniform sampler2D u_metallic_roughness_texture;  // G roughness, B metallic
layout(binding = 2) uniform sampler2D u_normal_texture;              // tangent space
layout(binding = 3) uniform sampler2D u_previous_layer_depth;        // depth of layer i-1

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
    vec4 base = m.base_color;
    if (m.flags.x != 0) base *= texture(u_base_color_texture, fs.uv);
    float metallic = m.params.x, roughness = m.params.y;
    if (m.flags.y != 0) {
        vec4 mr = texture(u_metallic_roughness_texture, fs.uv);
        roughness *= mr.g;
        metallic *= mr.b;
    }

    vec3 n = normalize(fs.view_normal);
    // glTF doubleSided: a back face shows the other side of the surface.
    if (!gl_FrontFacing && m.flags.w != 0) n = -n;
    if (m.flags.z != 0) {
        vec3 t = texture(u_normal_texture, fs.uv).xyz * 2.0 - 1.0;
        t.xy *= m.params.w;
        n = perturb_normal(n, fs.view_tangent, fs.view_position, fs.uv, normalize(t));
    }

    GSample g;
    g.albedo = base.rgb;
    g.metallic = clamp(metallic, 0.0, 1.0);
    g.normal = n;
    g.roughness = clamp(roughness, 0.0, 1.0);
    g.reflectivity = clamp(m.params.z, 0.0, 1.0);
    g.covered = true;
    gbuffer_encode(g, o_albedo_metallic, o_normal_roughness, o_material);
}
