#version 450 core
// reproject_reflection (Settings.reflection_reprojection "hit"): where each pixel's reflection was
// in the previous frame of the sequence, by the motion of what it reflects.
//
// A mirror shows the reflected point H at its mirror image I = H - 2 ((H - P) . N) N behind the
// surface point P; seen along the view ray it lies at the virtual point X = P + v |H - P|, the hit
// distance behind the surface (Stachowiak 2015's hit-point reprojection; FidelityFX SSSR's
// parallax-corrected one). In the previous frame H was where its object's transforms put it,
// H_prev, and the mirror where its own put it (P_prev, N_prev): the image moved by
// I_prev - I, and the reflection was at X_prev = X + (I_prev - I), which the previous camera
// projects. For what stood still this is the camera's parallax correction; for a hit that moved
// it follows the hit; a miss is a point at infinity along the ray, moved by the mirror's turn
// alone. The rays.hit of each ray give the hit's layer and pixel, whose object's transforms
// (the ones gbuffer.motion is made from) give H_prev; a hit the BVH found (rays.radiance's
// distance) has no object known here and counts as still. The reflection at a pixel is the
// resolve's combination of the rays of its reuse neighbourhood (a mirror's own ray only), so
// those rays, each hit taken as seen from this pixel's surface point, average their previous
// positions by their weights.
//
// Rejection: the position must show the same mirror in the previous frame (its object at layer 0,
// its normal within reject_normal), and what the previous frame reflected there must be what
// this frame's rays reflect: as large a share of hits (a hit against a miss differs) at the
// virtual depth this frame predicts for it (|X_prev|: camera to surface plus hit distance, within
// reject_reflection_depth). Where a moving object left a mirror, the previous frame reflected
// the object there, nearer than what it shows now: the disocclusion of a reflection, which no
// test of the surface sees. The previous frame's share and depth are accumulated over its
// history (reflection.hits), this frame's over the rays the resolve combined, so that one glossy
// ray's noise decides nothing. Where the reflected point's position fails, the surface's own (the
// reproject pass's, whose reflection must pass the same test: the reflected point as seen from
// the surface's previous position) is taken; where that fails too, the history is rejected
// (reason REFLECTION, or the surface's own reason). Positions keep the footprint's texels that
// pass (the nearest one where some fail), as the reproject pass does with reject_layers.
//   outputs: reprojection.reflection (RGBA32F: xy previous window position, z 1 = valid, w reason)
//            reflection.hits (RGBA32F: x share x virtual depth of the hits, y the share of the
//            rays' weight that hit, accumulated where the history is kept; w the frames
//            accumulated, 0 where the pixel traced nothing)
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/ssr_settings.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/scene_data.glsl"
#include "../lib/motion.glsl"
#include "../lib/object_motion.glsl"
#include "../lib/reprojection.glsl"

#ifndef RAY_RADIANCE
#define RAY_RADIANCE 0
#endif

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = TEXTURE_RAYS_HIT) uniform sampler2DArray u_hit;
layout(binding = TEXTURE_RAYS_SAMPLE) uniform sampler2DArray u_sample;
layout(binding = TEXTURE_RAYS_DIRECTION) uniform sampler2DArray u_direction;
layout(binding = TEXTURE_LINEAR_DEPTH) uniform sampler2DArray u_linear_depth;
layout(binding = TEXTURE_GBUFFER_NORMAL) uniform sampler2DArray u_normal;
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;
layout(binding = TEXTURE_REPROJECTION) uniform sampler2D u_reprojection;  // the surface's own (reproject pass)
#if RAY_RADIANCE
layout(binding = TEXTURE_RAYS_RADIANCE) uniform sampler2DArray u_ray_radiance;  // a >= 0: the BVH's hit distance
#endif
layout(binding = TEXTURE_PREVIOUS_GBUFFER_NORMAL) uniform sampler2DArray u_prev_normal;
layout(binding = TEXTURE_PREVIOUS_GBUFFER_MATERIAL) uniform sampler2DArray u_prev_material;
layout(binding = TEXTURE_PREVIOUS_REFLECTION_HITS) uniform sampler2D u_prev_hits;  // the previous frame's reflection.hits

layout(binding = IMAGE_REPROJECTION_REFLECTION, rgba32f) writeonly uniform image2D o_reprojection;
layout(binding = IMAGE_REFLECTION_HITS, rgba32f) writeonly uniform image2D o_hits;

uniform mat4 u_view_to_previous_view;  // V_prev V^-1 (the camera's part)
uniform mat4 u_previous_proj;          // the previous frame's projection without its jitter
uniform int u_has_history;
uniform vec2 u_jitter;                 // as the reproject pass adds it
uniform float u_reject_normal;
uniform float u_reject_reflection_depth;
uniform int u_max_history;  // the reflection's own (temporal_max_history or svgf_max_history)

vec2 previous_window(vec4 clip) {
    return (clip.xy / clip.w * 0.5 + 0.5) * frame.viewport.xy + u_jitter;
}

// Whether the previous frame's reflection at texel q showed what this pixel's rays show: as much
// of a hit (the shares of the rays' weight that hit differ by at most HALF: a hit where all was a
// miss, or the converse, differs) and, where hits make most of both, at the virtual depth `depth`
// (within reject_reflection_depth; where misses make most of a glossy reflection, its few hits'
// depths are noise). The previous values are accumulated over the history (reflection.hits), this
// frame's over the rays the resolve combined: neither is one glossy ray's.
const float HALF = 0.5;
bool same_reflection(ivec2 q, float depth, float share) {
    vec4 prev = texelFetch(u_prev_hits, q, 0);
    if (prev.w < 0.5 || abs(prev.y - share) > HALF) return false;  // no rays there; hit against miss
    if (min(share, prev.y) < HALF || u_reject_reflection_depth <= 0.0) return true;
    return abs(prev.x / prev.y - depth) <= u_reject_reflection_depth * depth;
}

// The candidate position `pos` of a reflection whose virtual depth is `depth` (share `share`):
// true where a texel of its 2x2 footprint shows the same reflection (and, with `mirror` >= 0, the
// same mirror: object and previous-view normal n_prev); `pos` moves to the nearest such texel
// where some differ (a bilinear fetch across an edge would mix the other history in).
bool footprint_agrees(inout vec2 pos, float depth, float share, int mirror, vec3 n_prev) {
    ivec2 size = ivec2(frame.viewport.xy);
    if (any(lessThan(pos, vec2(0.0))) || any(greaterThanEqual(pos, vec2(size)))) return false;
    ivec2 base = ivec2(floor(pos - 0.5));
    int matched = 0;
    float nearest = 1e30;
    ivec2 best = ivec2(0);
    for (int i = 0; i < 4; ++i) {
        ivec2 q = clamp(base + ivec2(i & 1, i >> 1), ivec2(0), size - 1);
        if (mirror >= 0) {
            vec4 m = texelFetch(u_prev_material, ivec3(q, 0), 0);
            if (m.g < 0.5 || gbuffer_object_id(m) != mirror) continue;
            if (dot(normalize(texelFetch(u_prev_normal, ivec3(q, 0), 0).xyz), n_prev) < u_reject_normal) continue;
        }
        if (!same_reflection(q, depth, share)) continue;
        matched |= 1 << i;
        vec2 d = vec2(q) + 0.5 - pos;
        if (dot(d, d) < nearest) {
            nearest = dot(d, d);
            best = q;
        }
    }
    if (matched != 0 && matched != 15) pos = vec2(best) + 0.5;
    return matched != 0;
}

void main() {
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) return;
    vec4 surface = texelFetch(u_reprojection, pixel, 0);
    ivec2 q = min(pixel / ssr.downscale, ivec2(ssr.trace_width, ssr.trace_height) - 1);
    vec4 material = texelFetch(u_material, ivec3(pixel, 0), 0);
    bool traced = material.g > 0.5 && texelFetch(u_sample, ivec3(q, 0), 0).w > 0.5;
    if (!traced) {
        // No rays, no reflected point: the surface's own reprojection (the reflection the
        // temporal passes accumulate there is the environment or none).
        imageStore(o_reprojection, pixel, surface);
        imageStore(o_hits, pixel, vec4(0.0));
        return;
    }
    int mirror = gbuffer_object_id(material);
    vec3 p = view_position(vec2(pixel) + 0.5, texelFetch(u_linear_depth, ivec3(pixel, 0), 0).r);
    vec3 n = normalize(texelFetch(u_normal, ivec3(pixel, 0), 0).xyz);
    vec3 v = normalize(p);
    mat4 camera = u_view_to_previous_view;
    mat4 mirror_motion = object_view_to_previous_view(camera, mirror);
    vec3 p_prev = (mirror_motion * vec4(p, 1.0)).xyz;
    vec3 n_prev = normal_to_previous(mirror_motion, n);
    // The rays the resolve combined into this pixel's reflection: its reuse neighbourhood's, of
    // the same mirror object (a mirror's own ray only), each hit taken as seen from this pixel's
    // surface point. Their reflected points' previous positions average, by the rays' weights,
    // into where the reflection was; their virtual depths (|P| + hit distance) and the share of
    // the weight that hit are what the previous frame's stored values are compared with (less
    // noisy than one glossy ray).
    float alpha = texelFetch(u_normal, ivec3(pixel, 0), 0).w;
    alpha *= alpha;
    int radius = alpha < 1e-4 || ssr.sampling == SAMPLING_MIRROR ? 0 : ssr.reuse_radius;
    ivec2 trace_size = ivec2(ssr.trace_width, ssr.trace_height);
    int rays = textureSize(u_hit, 0).z;
    float sum_w = 0.0, hit_w = 0.0, depth = 0.0, expect_hit = 0.0, expect_surface = 0.0;
    vec2 sum_pos = vec2(0.0);
    bool behind = false;  // a reflected point behind the previous camera: no position
    for (int dy = -radius; dy <= radius; ++dy) {
        for (int dx = -radius; dx <= radius; ++dx) {
            ivec2 nq = q + ivec2(dx, dy);
            if (any(lessThan(nq, ivec2(0))) || any(greaterThanEqual(nq, trace_size))) continue;
            ivec2 op = min(nq * ssr.downscale + ssr.downscale / 2, size - 1);
            vec4 m = texelFetch(u_material, ivec3(op, 0), 0);
            if (m.g < 0.5 || gbuffer_object_id(m) != mirror || texelFetch(u_sample, ivec3(nq, 0), 0).w < 0.5) continue;
            vec3 origin = view_position(vec2(op) + 0.5, texelFetch(u_linear_depth, ivec3(op, 0), 0).r);
            for (int r = 0; r < rays; ++r) {
                float w = texelFetch(u_sample, ivec3(nq, r), 0).x;
                if (w <= 0.0) continue;
                vec4 hit = texelFetch(u_hit, ivec3(nq, r), 0);
                vec3 dir = texelFetch(u_direction, ivec3(nq, r), 0).xyz;
                bool hits = hit.z > 0.5 && hit.w >= 0.5;
                vec3 h = vec3(0.0);
                mat4 hit_motion = camera;
                if (hits) {
                    ivec3 hp = ivec3(clamp(ivec2(hit.xy), ivec2(0), size - 1), int(hit.z) - 1);
                    h = view_position(hit.xy, texelFetch(u_linear_depth, hp, 0).r);
                    hit_motion = object_view_to_previous_view(camera, gbuffer_object_id(texelFetch(u_material, hp, 0)));
                }
#if RAY_RADIANCE
                float bvh = texelFetch(u_ray_radiance, ivec3(nq, r), 0).a;
                if (!hits && bvh >= 0.0) {
                    hits = true;
                    h = origin + dir * bvh;
                }
#endif
                vec4 clip;
                if (hits) {
                    vec3 h_prev = (hit_motion * vec4(h, 1.0)).xyz;
                    float d = distance(h, p);
                    vec3 image = h - 2.0 * dot(h - p, n) * n;
                    vec3 image_prev = h_prev - 2.0 * dot(h_prev - p_prev, n_prev) * n_prev;
                    vec3 x_prev = (camera * vec4(p + v * d, 1.0)).xyz + image_prev - (camera * vec4(image, 1.0)).xyz;
                    clip = u_previous_proj * vec4(x_prev, 1.0);
                    hit_w += w;
                    depth += w * (length(p) + d);
                    expect_hit += w * length(x_prev);
                    expect_surface += w * (length(p_prev) + distance(h_prev, p_prev));
                } else {
                    // A point at infinity along the ray: its image direction turns with the mirror only.
                    mat3 turn = mat3(camera);
                    vec3 x_prev = turn * v + reflect(turn * dir, n_prev) - turn * reflect(dir, n);
                    clip = u_previous_proj * vec4(x_prev, 0.0);
                }
                if (clip.w <= 0.0) behind = true;
                else sum_pos += w * previous_window(clip);
                sum_w += w;
            }
        }
    }
    float share = sum_w > 0.0 ? hit_w / sum_w : 0.0;
    depth = hit_w > 0.0 ? depth / hit_w : 0.0;
    // reflection.hits: (share x depth, share) accumulated like the reflection where its history is
    // kept, this frame's where it is not; w the frames accumulated (0: the pixel traced nothing).
    vec4 stats = vec4(share * depth, share, 0.0, sum_w > 0.0 ? 1.0 : 0.0);
    vec4 result = vec4(surface.xy, 0.0, surface.z > 0.5 ? REPROJECT_REFLECTION : surface.w);
    if (u_has_history == 0 || sum_w <= 0.0) {
        result = surface;
    } else {
        float scale = hit_w > 0.0 ? 1.0 / hit_w : 0.0;
        expect_hit *= scale;
        expect_surface *= scale;
        // The reflected point's previous position first; the surface's own where it fails.
        vec2 pos = sum_pos / sum_w;
        vec2 spos = surface.xy;
        if (!behind && footprint_agrees(pos, expect_hit, share, mirror, n_prev)) {
            result = vec4(pos, 1.0, REPROJECT_VALID);
        } else if (surface.z > 0.5 && footprint_agrees(spos, expect_surface, share, -1, n_prev)) {
            result = vec4(spos, 1.0, REPROJECT_VALID);
        }
        if (result.z > 0.5) {
            vec4 prev = texelFetch(u_prev_hits, clamp(ivec2(result.xy), ivec2(0), size - 1), 0);
            float n_acc = min(prev.w + 1.0, float(u_max_history));
            stats = vec4(mix(prev.xy, stats.xy, 1.0 / n_acc), 0.0, n_acc);
        }
    }
    imageStore(o_hits, pixel, stats);
    imageStore(o_reprojection, pixel, result);
}
