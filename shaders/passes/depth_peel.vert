#version 450 core
// Geometry pass with depth peeling (seed 000, 1.5.1 and 2.2): vertex stage.
#include "../lib/frame_uniforms.glsl"
#include "../lib/scene_data.glsl"

layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in vec4 a_tangent;
layout(location = 4) in vec4 a_color;  // glTF COLOR_0 (white without)
layout(location = 5) in vec2 a_uv1;    // glTF TEXCOORD_1 (set 0's copy without)

uniform int u_object;

#ifndef MOTION_VECTORS
#define MOTION_VECTORS 0
#endif
#if MOTION_VECTORS
#include "../lib/motion.glsl"
// The vertex through this frame's and the previous frame's transforms (lib/motion.glsl): both
// interpolate, perspective-correct, to the clip positions of the fragment's surface point.
out vec4 vs_motion_clip;
out vec4 vs_motion_previous_clip;
flat out int vs_motion_still;  // motion_still(): the fragment's motion is 0
#endif

out VertexOut {
    vec3 view_position;
    vec3 view_normal;
    vec4 uv;            // xy: TEXCOORD_0, zw: TEXCOORD_1 (each texture samples its own set)
    vec4 view_tangent;  // w: bitangent sign; all zero when the mesh has no tangents
    vec4 color;         // glTF COLOR_0: multiplies the base colour and its alpha
} vs;

// Every layer re-rasterises the same triangles: `invariant` guarantees bit-identical depth,
// so "strictly behind the previous layer" never rejects a surface by rounding.
invariant gl_Position;

void main() {
    ObjectData o = objects[u_object];
    vec4 view = frame.view * (o.model * vec4(a_position, 1.0));
    vs.view_position = view.xyz;
    vs.view_normal = mat3(frame.view) * (mat3(o.normal_matrix) * a_normal);
    vs.uv = vec4(a_uv, a_uv1);
    vs.color = a_color;
    vs.view_tangent = vec4(mat3(frame.view) * (mat3(o.model) * a_tangent.xyz), a_tangent.w);
    gl_Position = frame.proj * view;
#if MOTION_VECTORS
    vs_motion_clip = motion_clip(o, a_position);
    vs_motion_previous_clip = motion_previous_clip(u_object, a_position);
    vs_motion_still = int(motion_still(o, u_object));
#endif
}
