#version 450 core
// reproject (seed 002, 4.6.4, 4.6.5 and 4.7.4): for every pixel, its position in the previous
// frame of the sequence and whether the previous frame's history there belongs to the same
// surface. The position is the surface's own motion, gbuffer.motion (seed 002 4.6.4's velocity
// buffer, made from both frames' object and camera transforms): for what stood still it is the
// camera's reprojection (Listing 4.9), for what moved where that point was. History is rejected
// when the point lay off-screen, when the previous frame there shows another surface (the depth
// the transforms predict, Settings.reject_depth; with reject_layers the object too, and the
// deeper layers say whether the surface was hidden there: a disocclusion), or when the previous
// normal differs (Settings.reject_normal).
//   output (RGBA32F): xy previous window position in pixels (GL convention), z 1 = valid,
//                     w the reason (shaders/lib/reprojection.glsl)
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/scene_data.glsl"
#include "../lib/motion.glsl"
#include "../lib/object_motion.glsl"
#include "../lib/reprojection.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = TEXTURE_LINEAR_DEPTH) uniform sampler2DArray u_linear_depth;
layout(binding = TEXTURE_GBUFFER_NORMAL) uniform sampler2DArray u_normal;
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;
layout(binding = TEXTURE_PREVIOUS_LINEAR_DEPTH) uniform sampler2DArray u_prev_linear_depth;
layout(binding = TEXTURE_PREVIOUS_GBUFFER_NORMAL) uniform sampler2DArray u_prev_normal;
layout(binding = TEXTURE_PREVIOUS_GBUFFER_MATERIAL) uniform sampler2DArray u_prev_material;
layout(binding = TEXTURE_GBUFFER_MOTION) uniform sampler2DArray u_motion;  // gbuffer.motion: previous position - this one

layout(binding = IMAGE_REPROJECTION, rgba32f) writeonly uniform image2D o_reprojection;

uniform mat4 u_view_to_previous_clip;  // VP_prev * V_curr^-1
uniform mat4 u_previous_view_to_view;  // V_curr * V_prev^-1 (previous normals into this view)
uniform mat4 u_view_to_previous_view;  // V_prev * V_curr^-1
uniform int u_has_history;
// This frame's TAA jitter in pixels. The matrix leads to the previous frame's unjittered image;
// the point sampled at this pixel centre lies at centre - jitter in this frame's unjittered
// image, so adding the jitter gives where the unjittered pixel centre was (exact for a static
// camera, first order under motion). gbuffer.motion is taken from that unjittered point, so the
// centre plus the motion is the same position.
uniform vec2 u_jitter;
uniform float u_reject_depth;   // relative; 0: off
uniform float u_reject_normal;  // minimum cosine; -1: off
uniform int u_reject_offscreen;
uniform int u_reject_layers;

// Whether the previous frame's layer `layer` at texel q shows object `object` at positive view
// depth z (within reject_depth; any depth with the test off).
bool same_surface(ivec2 q, int layer, int object, float z) {
    vec4 m = texelFetch(u_prev_material, ivec3(q, layer), 0);
    if (m.g < 0.5 || gbuffer_object_id(m) != object) return false;
    return u_reject_depth <= 0.0 || abs(texelFetch(u_prev_linear_depth, ivec3(q, layer), 0).r - z) <= u_reject_depth * z;
}

void main() {
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) return;
    float z = texelFetch(u_linear_depth, ivec3(pixel, 0), 0).r;
    vec4 material = texelFetch(u_material, ivec3(pixel, 0), 0);
    bool covered = material.g > 0.5;
    int object = covered ? gbuffer_object_id(material) : -1;
    vec3 p = view_position(vec2(pixel) + 0.5, z);
    bool moved = u_has_history != 0 && object_moved(object);
    // The previous view depth the point's transforms predict (what the history there must show).
    mat4 to_previous_clip = moved ? frame.previous_view_proj * world_to_previous_world(object) * frame.inv_view
                                  : u_view_to_previous_clip;
    vec3 prev = reproject_to_previous(to_previous_clip, p, frame.viewport.xy);
    // A surface's previous position is its motion vector's; the environment's the camera's.
    vec2 pos = covered ? vec2(pixel) + 0.5 + texelFetch(u_motion, ivec3(pixel, 0), 0).xy : prev.xy + u_jitter;
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
        ivec2 base = ivec2(floor(pos - 0.5));
        ivec2 best_texel = clamp(ivec2(pos), ivec2(0), size - 1);
        if (u_reject_layers != 0) {
            // The footprint's texels whose layer 0 is this surface; the fetch reads those only
            // (the nearest one where some are another surface: a bilinear fetch across an edge
            // would mix the other surface's history in).
            int matched = 0;
            float nearest = 1e30;
            for (int i = 0; i < 4; ++i) {
                ivec2 q = clamp(base + ivec2(i & 1, i >> 1), ivec2(0), size - 1);
                if (!same_surface(q, 0, object, prev.z)) continue;
                matched |= 1 << i;
                vec2 d = vec2(q) + 0.5 - pos;
                if (dot(d, d) < nearest) {
                    nearest = dot(d, d);
                    best_texel = q;
                }
            }
            if (matched == 0) {
                // Not in layer 0: hidden behind it in the previous frame (a deeper layer shows it,
                // seed 000 1.5.1's layers: a disocclusion), or not there at all.
                reason = REPROJECT_DEPTH;
                int layers = textureSize(u_prev_material, 0).z;
                for (int layer = 1; layer < layers && reason != REPROJECT_DISOCCLUDED; ++layer)
                    for (int i = 0; i < 4; ++i)
                        if (same_surface(clamp(base + ivec2(i & 1, i >> 1), ivec2(0), size - 1), layer, object, prev.z))
                            reason = REPROJECT_DISOCCLUDED;
            } else if (matched != 15) {
                pos = vec2(best_texel) + 0.5;
            }
        } else {
            // The previous texel of the 2x2 footprint whose depth agrees best: a continuing surface
            // matches one of them even where depth changes fast across pixels (grazing floors).
            float best = 1e30;
            for (int i = 0; i < 4; ++i) {
                ivec2 q = clamp(base + ivec2(i & 1, i >> 1), ivec2(0), size - 1);
                if (texelFetch(u_prev_material, ivec3(q, 0), 0).g < 0.5) continue;
                float rel = abs(texelFetch(u_prev_linear_depth, ivec3(q, 0), 0).r - prev.z) / prev.z;
                if (rel < best) {
                    best = rel;
                    best_texel = q;
                }
            }
            if (u_reject_depth > 0.0 && best > u_reject_depth) reason = REPROJECT_DEPTH;
        }
        if (reason == REPROJECT_VALID) {
            vec3 n = normalize(texelFetch(u_normal, ivec3(pixel, 0), 0).xyz);
            vec3 n_prev = texelFetch(u_prev_normal, ivec3(best_texel, 0), 0).xyz;
            // A moved object's normals turned with it: the previous normal goes by its transforms.
            vec3 np = moved ? normal_from_previous(object_view_to_previous_view(u_view_to_previous_view, object), n_prev)
                            : normalize(mat3(u_previous_view_to_view) * n_prev);
            if (dot(n, np) < u_reject_normal) reason = REPROJECT_NORMAL;
        }
    }
    imageStore(o_reprojection, pixel, vec4(pos, reason == REPROJECT_VALID ? 1.0 : 0.0, reason));
}
