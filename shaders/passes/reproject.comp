#version 450 core
// reproject (seed 002, 4.6.5 and 4.7.4): for every pixel, its position in the previous frame
// of the sequence and whether the previous frame's history there belongs to the same
// surface. History is rejected when the point lay off-screen, when the previous depth around
// it differs by more than a relative epsilon (a disocclusion: a surface in front of it moved
// away), or when the previous normal differs (Settings.reject_*).
//   output (RGBA32F): xy previous window position in pixels (GL convention), z 1 = valid,
//                     w the reason (shaders/lib/reprojection.glsl)
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/reprojection.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler2DArray u_linear_depth;
layout(binding = 1) uniform sampler2DArray u_normal;
layout(binding = 2) uniform sampler2DArray u_material;
layout(binding = 3) uniform sampler2DArray u_prev_linear_depth;
layout(binding = 4) uniform sampler2DArray u_prev_normal;
layout(binding = 5) uniform sampler2DArray u_prev_material;

layout(binding = 0, rgba32f) writeonly uniform image2D o_reprojection;

uniform mat4 u_view_to_previous_clip;  // VP_prev * V_curr^-1
uniform mat4 u_previous_view_to_view;  // V_curr * V_prev^-1 (previous normals into this view)
uniform int u_has_history;
// This frame's TAA jitter in pixels. The matrix leads to the previous frame's unjittered image;
// the point sampled at this pixel centre lies at centre - jitter in this frame's unjittered
// image, so adding the jitter gives where the unjittered pixel centre was (exact for a static
// camera, first order under motion).
uniform vec2 u_jitter;
uniform float u_reject_depth;   // relative; 0: off
uniform float u_reject_normal;  // minimum cosine; -1: off
uniform int u_reject_offscreen;

void main() {
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) return;
    float z = texelFetch(u_linear_depth, ivec3(pixel, 0), 0).r;
    bool covered = texelFetch(u_material, ivec3(pixel, 0), 0).g > 0.5;
    vec3 p = view_position(vec2(pixel) + 0.5, z);
    vec3 prev = reproject_to_previous(u_view_to_previous_clip, p, frame.viewport.xy);
    vec2 pos = prev.xy + u_jitter;
    float reason = REPROJECT_VALID;
    if (u_has_history == 0) {
        reason = REPROJECT_NO_HISTORY;
    } else if (!covered) {
        reason = REPROJECT_NO_SURFACE;
    } else if (prev.z <= 0.0 || any(lessThan(pos, vec2(0.0))) || any(greaterThanEqual(pos, vec2(size)))) {
        if (u_reject_offscreen != 0 || prev.z <= 0.0) reason = REPROJECT_OFFSCREEN;
        pos = clamp(pos, vec2(0.5), vec2(size) - 0.5);
    }
    if (reason == REPROJECT_VALID) {
        // The previous texel of the 2x2 footprint whose depth agrees best: a continuing surface
        // matches one of them even where depth changes fast across pixels (grazing floors).
        ivec2 base = ivec2(floor(pos - 0.5));
        float best = 1e30;
        ivec2 best_texel = clamp(ivec2(pos), ivec2(0), size - 1);
        for (int i = 0; i < 4; ++i) {
            ivec2 q = clamp(base + ivec2(i & 1, i >> 1), ivec2(0), size - 1);
            if (texelFetch(u_prev_material, ivec3(q, 0), 0).g < 0.5) continue;
            float rel = abs(texelFetch(u_prev_linear_depth, ivec3(q, 0), 0).r - prev.z) / prev.z;
            if (rel < best) {
                best = rel;
                best_texel = q;
            }
        }
        if (u_reject_depth > 0.0 && best > u_reject_depth) {
            reason = REPROJECT_DEPTH;
        } else {
            vec3 n = normalize(texelFetch(u_normal, ivec3(pixel, 0), 0).xyz);
            vec3 np = normalize(mat3(u_previous_view_to_view) * texelFetch(u_prev_normal, ivec3(best_texel, 0), 0).xyz);
            if (dot(n, np) < u_reject_normal) reason = REPROJECT_NORMAL;
        }
    }
    imageStore(o_reprojection, pixel, vec4(pos, reason == REPROJECT_VALID ? 1.0 : 0.0, reason));
}
