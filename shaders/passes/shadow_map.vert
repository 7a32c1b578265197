#version 450 core
// Shadow map of the directional light that casts one: depth only, orthographic.
#include "../lib/scene_data.glsl"

layout(location = 0) in vec3 a_position;
layout(location = 2) in vec2 a_uv;
layout(location = 4) in vec4 a_color;
layout(location = 5) in vec2 a_uv1;

uniform int u_object;
uniform mat4 u_light_view_proj;  // world -> light clip space

// For an alpha-tested material's fragment stage (passes/shadow_map.frag): both texture coordinate
// sets and COLOR_0's alpha, a factor of the base colour's.
out vec4 v_uv;
out float v_alpha;

void main() {
    v_uv = vec4(a_uv, a_uv1);
    v_alpha = a_color.a;
    gl_Position = u_light_view_proj * (objects[u_object].model * vec4(a_position, 1.0));
}
