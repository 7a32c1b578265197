#version 450 core
// resolve (seed 000, 2.4): turns ray results into each pixel's reflection colour.
// Every ray brings the lit colour of the layer it hit (faded toward the environment), or the
// environment if it missed. Each pixel combines its own rays with its neighbours' within
// `reuse_radius` (radius 1: the thesis's 3x3, Stachowiak's ray reuse):
//   thesis weights: every ray keeps the weight it was traced with (seed 000, 2.4.1);
//   brdf weights:   a neighbour's ray is reweighted by this pixel's BRDF over the pdf the
//                   neighbour sampled it with (Stachowiak 2015), toward that ray's hit point.
// With edge-aware reuse, a neighbour also counts by the similarity of its depth and normal,
// which keeps reflections from bleeding across silhouettes and is what upsamples rays traced
// at 1/2 or 1/4 resolution (thesis 2.6). As in the thesis, a work group first fetches every
// ray its pixels can reuse into shared memory once, then every pixel sums from there; the
// group is 16x16 pixels with an apron of `reuse_radius` trace pixels (the thesis used 32x32
// groups whose edge pixels only fetch). Where the passes read by imageLoad (llvmpipe, where a
// shared-memory load costs more than the image load it would save), resolve_fetch.comp fetches
// every ray once into textures instead, and the pixels sum from those (RESOLVE_SHARED_TILE 0):
// the same sums.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/ssr_settings.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/brdf.glsl"
#include "../lib/random.glsl"
#include "../lib/ggx_sampling.glsl"
#include "../lib/ray_generation.glsl"
#include "../lib/environment.glsl"
#include "../lib/non_receiver.glsl"
#include "../lib/input_fetch.glsl"
#include "../lib/resolve_ray.glsl"

#ifndef OWN_RAYS_ONLY
#define OWN_RAYS_ONLY 0
#endif
// 1: the group fills a shared tile with its neighbours' rays (the thesis's design);
// 0: they come from resolve_fetch's textures by imageLoad (FETCH_BY_IMAGE: llvmpipe, whose
// shared-memory loads go one lane and one component at a time through the stack; passes/resolve.cpp).
#ifndef RESOLVE_SHARED_TILE
#define RESOLVE_SHARED_TILE 1
#endif
#if !OWN_RAYS_ONLY && !RESOLVE_SHARED_TILE
layout(binding = IMAGE_RESOLVE_RAY_COLOR, rgba32f) readonly uniform image2DArray u_ray_color;   // resolve_fetch.comp
layout(binding = IMAGE_RESOLVE_RAY_TARGET, rgba32f) readonly uniform image2DArray u_ray_target;
#endif
// Settings.skip: the dispatch runs over the classify pass's resolve list
// (resolve_list.glsl): one invocation per receiving pixel for the own-rays resolve, one group
// per 16x16 tile holding a receiver for the tiled one. The classify pass wrote every other
// pixel's reflection (0, or the environment where the surface is rougher than the cutoff).
#ifndef RESOLVE_LIST
#define RESOLVE_LIST 0
#endif
#if RESOLVE_LIST
#include "../lib/resolve_list.glsl"
#endif

#if RESOLVE_LIST && OWN_RAYS_ONLY
layout(local_size_x = 64, local_size_y = 1, local_size_z = 1) in;
#else
layout(local_size_x = 16, local_size_y = 16, local_size_z = 1) in;
#endif

// Settings the per-ray and per-neighbour loops read, read once at the start of main:
// llvmpipe (Mesa 22.3) reads a uniform-block value lane by lane, with a bounds check per lane,
// wherever lane 0 may be masked off (in a loop, an if, or after a return).
int g_rays_per_pixel, g_edge_aware, g_reuse_weighting;
float g_edge_depth_sigma, g_edge_normal_power;

layout(binding = IMAGE_REFLECTION, rgba16f) writeonly uniform image2D o_reflection;

#if defined(TEMPORAL_RAY_REUSE) && TEMPORAL_RAY_REUSE
// Ray-result reuse over time (seed 000, 4.4): the previous frame traced rays from (nearly) the
// same surface points; where the reprojection keeps this pixel's history, the rays of the
// previous frame's reuse neighbourhood around the reprojected pixel join as extra neighbours,
// doubling the rays each pixel averages at no tracing cost. They are weighted exactly as this
// frame's neighbours, after moving their origins, directions and hit points into this view: by
// the camera's change, and by their object's where it moved (lib/object_motion.glsl). A ray
// whose hit's object moved otherwise than its origin's no longer goes where it went: it is left
// out.
#include "../lib/scene_data.glsl"
#include "../lib/motion.glsl"
#include "../lib/object_motion.glsl"
layout(binding = TEXTURE_PREVIOUS_RAYS_HIT) uniform sampler2DArray u_prev_hit;
layout(binding = TEXTURE_PREVIOUS_RAYS_SAMPLE) uniform sampler2DArray u_prev_sample;
layout(binding = TEXTURE_PREVIOUS_RAYS_DIRECTION) uniform sampler2DArray u_prev_direction;
layout(binding = TEXTURE_PREVIOUS_LIT) uniform sampler2DArray u_prev_lit;
layout(binding = TEXTURE_PREVIOUS_LINEAR_DEPTH) uniform sampler2DArray u_prev_linear_depth;
layout(binding = TEXTURE_PREVIOUS_GBUFFER_NORMAL) uniform sampler2DArray u_prev_normal;
layout(binding = TEXTURE_PREVIOUS_GBUFFER_MATERIAL) uniform sampler2DArray u_prev_material;
uniform int u_has_previous_rays;
uniform mat4 u_previous_view_to_view;  // V_curr * V_prev^-1
uniform mat4 u_view_to_previous_view;  // V_prev * V_curr^-1
uniform vec4 u_previous_proj;          // previous (jittered) proj [0][0], [1][1], [2][0], [2][1]

// view_position (depth_convention.glsl) with the previous frame's projection; previous view space.
vec3 previous_view_position(vec2 pix, float z) {
    vec2 ndc = pix * frame.viewport.zw * 2.0 - 1.0;
    return vec3((ndc + u_previous_proj.zw) * z / u_previous_proj.xy, -z);
}
#endif

const int GROUP = 16;
const int MAX_TILE = GROUP + 2 * 2;  // reuse radius <= 2, downscale 1 is the widest tile
const int TILE_ENTRIES = MAX_TILE * MAX_TILE;
// Ray slots: two rays of the widest tile. 32 004 bytes of shared memory in all, within
// the 32 KiB every OpenGL 4.3 device offers; at full resolution and radius 1, 4 rays now take two
// chunks instead of four (each chunk pays two barriers, the origins and every neighbour's edge weight).
const int TILE_CAPACITY = 2 * TILE_ENTRIES;

#if !OWN_RAYS_ONLY && RESOLVE_SHARED_TILE
// Ray data of a chunk of rays of every trace pixel in the tile, entry (ray - chunk start) *
// entries + tile entry: as many rays as fit in TILE_CAPACITY entries per chunk (each
// chunk costs two barriers, which llvmpipe pays dearly; up to 8 rays at half resolution fit in one).
// A pixel reads 8 floats per reused ray and 4 per neighbour (was 9 and 6): llvmpipe
// (Mesa 22.3) loads shared memory one lane and one component at a time, so these reads, 36 rays
// per pixel at the thesis's configuration, cost more than the arithmetic on them.
shared vec4 s_color[TILE_CAPACITY];     // rgb: radiance the ray brings; a: its weight
// xyz: the view position of the ray's hit (origin + direction * distance), or its view direction
// if it missed, so that a pixel's direction toward it is xyz - p (hit) or xyz (miss), computed
// once per tile entry rather than by every pixel that reuses the ray; w: the pdf its direction
// was sampled with, negated for a miss (a pdf of 0, which is never reweighted, needs no flag).
shared vec4 s_target[TILE_CAPACITY];
shared vec4 s_surface[TILE_ENTRIES];   // xyz: the origin's view normal; w: its view z (edge weights)
#endif
shared uint s_any_receiver;

// Similarity of a neighbour's surface to this pixel's: relative depth difference and normal
// cosine (a cross-bilateral weight, Kopf et al. 2007; seed 002, 4.7.4).
float edge_weight(vec3 p, vec3 n, vec3 pq, vec3 nq) {
    float dz = abs(p.z - pq.z) / max(-p.z, 1e-4);
    return exp(-dz / g_edge_depth_sigma) * pow(max(dot(n, nq), 0.0), g_edge_normal_power);
}

void main() {
    g_rays_per_pixel = ssr.rays_per_pixel;
    g_edge_aware = ssr.edge_aware;
    g_reuse_weighting = ssr.reuse_weighting;
    g_edge_depth_sigma = ssr.edge_depth_sigma;
    g_edge_normal_power = ssr.edge_normal_power;
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 trace_size = ivec2(ssr.trace_width, ssr.trace_height);
    int s = ssr.downscale, radius = ssr.reuse_radius;
#if RESOLVE_LIST && OWN_RAYS_ONLY
    uint index = resolve_list_index();
    if (index >= resolve_list.count) return;
    ivec2 pixel = resolve_list_unpack(resolve_list.entries[index]);
#else
#if RESOLVE_LIST
    uint tile_index = resolve_list_index();
    if (tile_index >= resolve_list.count) return;  // the whole group: past the list's last row
    ivec2 group_origin = resolve_list_unpack(resolve_list.entries[tile_index]) * GROUP;
#else
    ivec2 group_origin = ivec2(gl_WorkGroupID.xy) * GROUP;
#endif
    ivec2 tile_lo = group_origin / s - radius;
    ivec2 tile_dim = (group_origin + GROUP - 1) / s + radius - tile_lo + 1;
    int entries = tile_dim.x * tile_dim.y;
    int lid = int(gl_LocalInvocationIndex);
    ivec2 pixel = group_origin + ivec2(gl_LocalInvocationID.xy);
#endif
    bool inside = all(lessThan(pixel, size));
    GSample g = gsample(min(pixel, size - 1));
    bool receives = inside && is_reflective(g);
    vec3 p = view_pos(min(pixel, size - 1));
    vec3 v = normalize(-p);
    mat3 tbn = frame_from_normal(g.normal);
    mat3 to_local = transpose(tbn);
    vec3 v_local = to_local * v;
    float alpha = g.roughness * g.roughness;
    bool mirror_receiver = alpha < 1e-4 || ssr.sampling == SAMPLING_MIRROR;
    ivec2 base = pixel / s;
    vec3 sum_c = vec3(0.0);
    float sum_w = 0.0;

#if !OWN_RAYS_ONLY && !RESOLVE_LIST && RESOLVE_SHARED_TILE
    // A group none of whose pixels receives rays (most of a frame: sky, rough or
    // non-reflective surfaces) needs no ray data at all; it writes what a non-receiving pixel
    // writes below and leaves, skipping the tile fetches. One group vote costs two barriers.
    if (lid == 0) s_any_receiver = 0u;
    barrier();
    if (receives) atomicOr(s_any_receiver, 1u);
    barrier();
    if (s_any_receiver == 0u) {
        if (inside) imageStore(o_reflection, pixel, vec4(non_receiver_reflection(g, v), 1.0));
        return;
    }
#endif

#if OWN_RAYS_ONLY
    // Full-resolution rays whose neighbours weigh nothing here (reuse radius 0, or mirror rays
    // with BRDF weights: a mirror ray serves only its own pixel): each pixel fetches its own
    // rays directly, with no tile, shared memory, group vote or barrier. The same sums as the
    // tiled path below, term for term.
    if (receives && FETCH(u_sample, ivec3(base, 0)).w > 0.5) {
        for (int r = 0; r < g_rays_per_pixel; ++r) {
            RayResult ray = fetch_ray(base, r, p, size);
            if (ray.color.a <= 0.0) continue;
            // The edge weight of a pixel's own rays (edge_weight(p, n, p, n)) is one factor
            // common to every term: it cancels in the mean (on llvmpipe its exp and
            // pow ran per ray, taken or not).
            float w = ray.color.a;
            sum_c += w * ray.color.rgb;
            sum_w += w;
        }
    }
#else
    // The receiver's part of every BRDF weight below (brdf.glsl: brdf_cosine_over_pdf).
    float nv = dot(g.normal, v);
    float receiver = brdf_cosine_receiver(nv, alpha);
    // Chunks of rays: as many rays per chunk as the shared tile holds.
    int chunk = max(1, TILE_CAPACITY / entries);
    for (int r0 = 0; r0 < g_rays_per_pixel; r0 += chunk) {
        int rays = min(chunk, g_rays_per_pixel - r0);
#if RESOLVE_SHARED_TILE
        if (r0 > 0) barrier();  // every pixel has summed the previous chunk
        // Fetch rays r0 .. r0 + rays - 1 of every trace pixel in the tile once: hit colour,
        // weight, hit point or direction, pdf (what every pixel reusing them needs, precomputed
        // here), and with the first chunk the trace pixel's surface. Every shared
        // array is written once per entry (llvmpipe stores shared memory one lane at a time), and
        // the rays' origin is recomputed per chunk instead of passing through shared memory.
        for (int e = lid; e < entries; e += GROUP * GROUP) {
            ivec2 q = tile_lo + ivec2(e % tile_dim.x, e / tile_dim.x);
            vec3 origin = vec3(0.0);
            bool traced = false;
            vec3 normal = vec3(0.0, 0.0, 1.0);
            if (all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, trace_size))) {
                ivec2 op = min(q * s + s / 2, size - 1);
                traced = FETCH(u_sample, ivec3(q, 0)).w > 0.5;
                origin = view_pos(op);
                if (r0 == 0) normal = gsample(op).normal;
            }
            if (r0 == 0) s_surface[e] = vec4(normal, origin.z);
            for (int k = 0; k < rays; ++k) {
                vec4 color, target;
                reusable_ray(q, r0 + k, origin, traced, size, color, target);
                s_color[k * entries + e] = color;
                s_target[k * entries + e] = target;
            }
        }
        barrier();
#endif
        if (!receives) continue;
        // Neighbours outer, rays inner: a neighbour's edge weight depends on it alone, so it is
        // computed once for all its rays, and a neighbour it zeroes adds nothing (the
        // sums' order changes, by float rounding only). Every ray runs the same instructions, the
        // cases chosen by selects: llvmpipe runs 8 pixels in SIMD lanes and executes a branch
        // that any lane takes for all of them, masked.
        for (int dy = -radius; dy <= radius; ++dy) {
            for (int dx = -radius; dx <= radius; ++dx) {
                ivec2 q = base + ivec2(dx, dy);
                if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, trace_size))) continue;
#if RESOLVE_SHARED_TILE
                ivec2 t = q - tile_lo;
                int e = t.y * tile_dim.x + t.x;
                vec4 surface = s_surface[e];
#else
                // A neighbour that traced nothing has rays of weight 0, which add nothing.
                if (FETCH(u_sample, ivec3(q, 0)).w <= 0.5) continue;
                ivec2 op = min(q * s + s / 2, size - 1);
                vec4 surface = vec4(gsample(op).normal, view_pos(op).z);
#endif
                bool own = s == 1 && dx == 0 && dy == 0;
                float edge = g_edge_aware != 0 ? edge_weight(p, g.normal, vec3(0.0, 0.0, surface.w), surface.xyz) : 1.0;
                if (edge == 0.0) continue;
                // BRDF weights: a neighbour's ray by this pixel's BRDF toward the ray's hit point
                // (along its direction if it missed) over its pdf; mirror rays (pdf 0) keep their
                // weight at reduced resolution and only serve their own pixel at full resolution.
                bool reweigh = g_reuse_weighting == REUSE_WEIGHTING_BRDF && !own;
                for (int k = 0; k < rays; ++k) {
#if RESOLVE_SHARED_TILE
                    int slot = k * entries + e;
                    vec4 rc = s_color[slot];
#else
                    vec4 rc = imageLoad(u_ray_color, ivec3(q, r0 + k));
#endif
                    float w = rc.a;
                    if (reweigh) {
#if RESOLVE_SHARED_TILE
                        vec4 target = s_target[slot];
#else
                        vec4 target = imageLoad(u_ray_target, ivec3(q, r0 + k));
#endif
                        float pdf = abs(target.w);
                        vec3 l = target.w > 0.0 ? target.xyz - p : target.xyz;
                        l *= inversesqrt(dot(l, l));
                        float wb = brdf_cosine_over_pdf(g.normal, v, l, alpha, receiver, pdf);
                        w = pdf > 0.0 && !mirror_receiver ? wb : (s == 1 ? 0.0 : w);
                    }
                    w = rc.a > 0.0 ? w * edge : 0.0;  // a ray of weight <= 0 adds nothing
                    sum_c += w * rc.rgb;
                    sum_w += w;
                }
            }
        }
    }
#endif
#if defined(TEMPORAL_RAY_REUSE) && TEMPORAL_RAY_REUSE
    vec4 rp = texelFetch(u_reprojection, min(pixel, size - 1), 0);
    if (receives && u_has_previous_rays != 0 && rp.z > 0.5) {
        ivec2 prev_base = clamp(ivec2(floor(rp.xy)), ivec2(0), size - 1) / s;
        int prev_rays = textureSize(u_prev_hit, 0).z;
        for (int dy = -radius; dy <= radius; ++dy) {
            for (int dx = -radius; dx <= radius; ++dx) {
                ivec2 q = prev_base + ivec2(dx, dy);
                if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, trace_size))) continue;
                if (texelFetch(u_prev_sample, ivec3(q, 0), 0).w < 0.5) continue;  // did not trace
                ivec2 op = min(q * s + s / 2, size - 1);
                vec3 o_prev = previous_view_position(vec2(op) + 0.5, texelFetch(u_prev_linear_depth, ivec3(op, 0), 0).r);
                // The previous view -> this view for the origin's object (the camera's alone where
                // it stood still).
                int origin_object = gbuffer_object_id(texelFetch(u_prev_material, ivec3(op, 0), 0));
                bool origin_moved = object_moved(origin_object);
                mat4 to_view = origin_moved ? inverse(object_view_to_previous_view(u_view_to_previous_view, origin_object))
                                            : u_previous_view_to_view;
                mat3 rot = mat3(to_view);
                vec3 origin = (to_view * vec4(o_prev, 1.0)).xyz;
                vec3 nq = origin_moved ? normalize(transpose(inverse(rot)) * texelFetch(u_prev_normal, ivec3(op, 0), 0).xyz)
                                       : normalize(rot * texelFetch(u_prev_normal, ivec3(op, 0), 0).xyz);
                bool own = s == 1 && dx == 0 && dy == 0;
                for (int r = 0; r < prev_rays; ++r) {
                    vec4 smp = texelFetch(u_prev_sample, ivec3(q, r), 0);
                    if (smp.x <= 0.0) continue;
                    vec4 hit = texelFetch(u_prev_hit, ivec3(q, r), 0);
                    bool hits = hit.z > 0.5;
                    ivec3 hp = ivec3(clamp(ivec2(hit.xy), ivec2(0), size - 1), max(int(hit.z) - 1, 0));
                    if (hits) {
                        int hit_object = gbuffer_object_id(texelFetch(u_prev_material, hp, 0));
                        if (hit_object != origin_object && (origin_moved || object_moved(hit_object))) continue;
                    }
                    vec3 dir = rot * texelFetch(u_prev_direction, ivec3(q, r), 0).xyz;
                    if (origin_moved) dir = normalize(dir);
                    vec3 c = environment_view(dir);
                    vec3 hit_pos = vec3(0.0);
                    if (hits) {
                        c = mix(c, texelFetch(u_prev_lit, hp, 0).rgb, hit.w);
                        vec3 h_prev = previous_view_position(hit.xy, texelFetch(u_prev_linear_depth, hp, 0).r);
                        hit_pos = (to_view * vec4(h_prev, 1.0)).xyz;
                    }
                    float w = smp.x;
                    if (g_reuse_weighting == REUSE_WEIGHTING_BRDF && !own) {
                        if (smp.y > 0.0 && !mirror_receiver) {
                            vec3 l = hits ? normalize(hit_pos - p) : dir;
                            w = brdf_cosine(v_local, transpose(tbn) * l, alpha) / smp.y;
                        } else if (s == 1) {
                            w = 0.0;
                        }
                    }
                    if (g_edge_aware != 0) w *= edge_weight(p, g.normal, origin, nq);
                    sum_c += w * c;
                    sum_w += w;
                }
            }
        }
    }
#endif
    if (!inside) return;
    vec3 reflection = vec3(0.0);
    if (receives) {
        reflection = sum_w > 1e-8 ? sum_c / sum_w : environment_view(reflect(-v, g.normal));
    } else {
#if !(RESOLVE_LIST && OWN_RAYS_ONLY)  // the list holds receivers only (llvmpipe runs a branch taken or not)
        reflection = non_receiver_reflection(g, v);
#endif
    }
    imageStore(o_reflection, pixel, vec4(reflection, 1.0));
}
