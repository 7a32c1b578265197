#version 450 core
// Shadow map of the directional light that casts one: depth only, orthographic.
#include "../lib/scene_data.glsl"

layout(location = 0) in vec3 a_position;
layout(location = 2) in vec2 a_uv;

uniform int u_object;
uniform mat4 u_light_view_proj;  // world -> light clip space

out vec2 v_uv;  // for an alpha-tested material's fragment stage (passes/shadow_map.frag)

void main() {
    v_uv = a_uv;
    gl_Position = u_light_view_proj * (objects[u_object].model * vec4(a_position, 1.0));
}
