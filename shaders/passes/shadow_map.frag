#version 450 core
// Shadow map: the fragment stage of alpha-tested materials only (glTF MASK, BLEND at 0.5). Their
// holes let the light through, as the G-buffer and the BVH traversals see them (the same test:
// lib/material.glsl's material_alpha_hole). Opaque materials draw without a fragment stage.
#include "../lib/scene_data.glsl"

layout(binding = TEXTURE_MATERIAL_BASE_COLOR) uniform sampler2D u_base_color_texture;
uniform int u_object;

in vec4 v_uv;  // both sets (texture_set)
in float v_alpha;

void main() {
    MaterialData m = materials[objects[u_object].material.x];
    vec4 base_texel = sample_material_texture(u_base_color_texture, m, 0, v_uv, dFdxFine(v_uv), dFdyFine(v_uv));
    float alpha = m.base_color.a * (m.flags.x != 0 ? base_texel.a : 1.0) * v_alpha;
    if (m.emissive.w >= 0.0 && alpha < m.emissive.w) discard;
}
