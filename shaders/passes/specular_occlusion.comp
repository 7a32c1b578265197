#version 450 core
// specular_occlusion: what a reflection ray that screen space did not resolve (a miss, or the
// faded share of a hit near the border) brings instead of the bare environment. The
// environment is the right answer only where the ray escapes into the open; where the scene
// closes around it (a room's walls, a column beside the floor) the sky is too bright. Each
// unresolved ray gets
//     radiance = V * environment(ray) + (1 - V) * occluder,
// V the estimated share of the ray (or lobe) that escapes, `occluder` an estimate of the
// radiance of what blocks it, and writes it to rays.radiance where the environment stood (the
// resolve, cone_trace and blur_mips read it as they read a fallback's radiance). Two
// estimators of V (Settings.specular_occlusion):
//   METHOD 1, "horizon": GTSO (Jimenez, Wu, Pesce and Jarabo 2016, "Practical Real-Time
//     Strategies for Accurate Indirect Occlusion", sections 4 and 5): horizon-based ambient
//     occlusion over layer 0's depth in SLICES screen slices gives the cosine-weighted
//     visibility and the bent normal; the visible region is the cone around the bent normal
//     with cos(aperture) = sqrt(1 - visibility); a ray is visible by the angle between it and
//     the bent normal (a mirror ray, or each stochastic ray), a lobe by the solid angle the
//     cone shares with the lobe's cone (the cap-cap overlap of Oat and Sander 2007, "Ambient
//     aperture lighting"), over the lobe's. The occluder's radiance: the lit colour of the
//     samples that set the horizons, weighted by the angle each blocks.
//   METHOD 2, "exit": where the ray left the screen. The ray is clipped to the view; at its
//     exit pixel the deep G-buffer's layers give the first surface at or behind the ray (the
//     ray passes in front of it). No surface: the ray leaves into open sky (V = 1). A surface
//     whose plane the ray runs toward (n . d < 0) is taken to continue beyond the screen: the
//     ray meets the plane after t, and V = 1 - exp(-t / (EXIT_REACH * depth)), a confidence
//     that shrinks with how far the plane must be extrapolated relative to its distance to
//     the camera. A plane the ray moves away from (a floor it rises above) does not block it.
//     A ray behind every layer there went into hidden space: V = 0. The occluder's radiance:
//     the lit colour of that surface at the exit pixel (the wall seen at the screen edge).
// LOBE 1 (glossy "cone" and "blur_mips": one mirror ray per pixel whose misses take the
// lobe-averaged environment, lib/glossy_common.glsl): the same over the lobe's 16 fixed VNDF
// directions. A ray screen space resolved (a hit at full fade weight) writes -2 ("not a
// fallback ray"), every other a = -1 (no hit distance, as the environment). Counters (binding
// 14): unresolved rays and occluded ones (V < 0.5), once per ray (the CPU device's atomics are
// slow in a loop: only those two, after the estimate).
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/ssr_settings.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/environment.glsl"
#include "../lib/brdf.glsl"
#include "../lib/random.glsl"
#include "../lib/ggx_sampling.glsl"
#include "../lib/screen_ray.glsl"
#include "../lib/cone_angle.glsl"

#ifndef METHOD
#define METHOD 2
#endif
#ifndef LOBE
#define LOBE 0
#endif
#ifndef FADED_HITS
#define FADED_HITS 1
#endif

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler2DArray u_linear_depth;
layout(binding = 1) uniform sampler2DArray u_normal;
layout(binding = 2) uniform sampler2DArray u_material;
layout(binding = 3) uniform sampler2DArray u_lit;
layout(binding = 4) uniform sampler2DArray u_ray_hit;
layout(binding = 5) uniform sampler2DArray u_ray_sample;
layout(binding = 6) uniform sampler2DArray u_ray_direction;
layout(binding = 7) uniform sampler2DArray u_albedo;
layout(binding = 0, rgba32f) writeonly uniform image2DArray o_radiance;
layout(std430, binding = 14) buffer OcclusionCounters {
    uint unresolved;
    uint occluded;
} counters;

layout(location = 0) uniform int u_rays;  // rays per trace pixel (layers of rays.*)

const int SLICES = 4;         // horizon: screen slices (GTAO's directions)
const int STEPS = 8;          // horizon: depth samples per side of a slice
const float RADIUS = 0.25;    // horizon: search radius, fraction of the image height
const float EXIT_REACH = 1.0; // exit: extrapolation scale, in units of the surface's view depth
const int LOBE_SAMPLES = 16;
#ifndef MARCH_STEPS
#define MARCH_STEPS 16        // exit: samples of the ray's way to the exit
#endif
#ifndef HIDDEN_DEPTH
#define HIDDEN_DEPTH 1.0     // exit: how far behind a surface (relative to its depth) still counts as hidden by it
#endif  // as lib/glossy_common.glsl's ENV_LOBE_SAMPLES

ivec2 g_size;
int g_layers;

vec3 env_view(vec3 d) {
    return environment_radiance(normalize(mat3(frame.inv_view) * d));
}

bool covered(ivec2 p, int layer) {
    return texelFetch(u_material, ivec3(p, layer), 0).g > 0.5;
}

// ---- METHOD 1: the horizon's visibility cone (GTSO) -------------------------------------------

struct Cone {
    vec3 bent;           // unit, view space
    float aperture;      // radians
    vec3 occluder;       // radiance of what sets the horizons
    float occluder_w;
};

Cone horizon_cone(ivec2 p, vec3 pos, vec3 n) {
    vec3 v = normalize(-pos);
    float radius_px = RADIUS * frame.viewport.y;
    // A per-pixel rotation of the slices and offset of the steps (4x4 interleaved, as GTAO's
    // noise; deterministic), so neighbouring pixels sample different directions.
    int cell = (p.x & 3) + 4 * (p.y & 3);
    float rot = float((cell * 7) & 15) / 16.0;
    float jit = float((cell * 11 + 5) & 15) / 16.0;
    vec3 bent = vec3(0.0);
    float vis = 0.0, wsum = 0.0;
    vec3 occ = vec3(0.0);
    float occ_w = 0.0;
    for (int s = 0; s < SLICES; ++s) {
        float phi = (float(s) + rot) * PI / float(SLICES);
        vec2 dir2 = vec2(cos(phi), sin(phi));
        // The slice: the plane through v and the screen direction (GTAO's approximation of
        // the view-space direction of a screen direction by (dir2, 0)).
        vec3 u = vec3(dir2, 0.0) - dot(vec3(dir2, 0.0), v) * v;
        u = normalize(u);
        vec3 axis = cross(u, v);
        vec3 np = n - axis * dot(n, axis);
        float np_len = length(np);
        if (np_len < 1e-4) continue;
        float n_ang = atan(dot(np, u), dot(np, v));
        float h[2];
        for (int side = 0; side < 2; ++side) {
            float sgn = side == 0 ? -1.0 : 1.0;
            float best = -1.0;
            vec3 best_c = vec3(0.0);
            for (int k = 0; k < STEPS; ++k) {
                float t = (float(k) + jit) / float(STEPS);
                vec2 q = vec2(p) + 0.5 + sgn * dir2 * max(t * t * radius_px, 1.0);
                ivec2 qi = ivec2(floor(q));
                if (any(lessThan(qi, ivec2(0))) || any(greaterThanEqual(qi, g_size))) break;
                if (!covered(qi, 0)) continue;
                vec3 sp = view_position(vec2(qi) + 0.5, texelFetch(u_linear_depth, ivec3(qi, 0), 0).r);
                vec3 w = sp - pos;
                float c = dot(w, v) * inversesqrt(max(dot(w, w), 1e-12));
                if (c > best) {
                    best = c;
                    best_c = texelFetch(u_lit, ivec3(qi, 0), 0).rgb;
                }
            }
            float hs = sgn * acos(clamp(best, -1.0, 1.0));
            // Clamped to the hemisphere around the projected normal (GTAO eq. 10).
            hs = side == 0 ? n_ang + max(hs - n_ang, -0.5 * PI) : n_ang + min(hs - n_ang, 0.5 * PI);
            h[side] = hs;
            float blocked = 0.5 * PI - abs(hs - n_ang);  // the angle this side's horizon blocks
            occ += np_len * blocked * best_c;
            occ_w += np_len * blocked;
        }
        // Cosine-weighted visible arc (GTAO eq. 7, its inner integral in closed form).
        float a = 0.25 * (-cos(2.0 * h[0] - n_ang) + cos(n_ang) + 2.0 * h[0] * sin(n_ang)) +
                  0.25 * (-cos(2.0 * h[1] - n_ang) + cos(n_ang) + 2.0 * h[1] * sin(n_ang));
        vis += np_len * a;
        wsum += np_len;
        float b = 0.5 * (h[0] + h[1]);
        bent += np_len * (v * cos(b) + u * sin(b));
    }
    Cone c;
    float visibility = wsum > 0.0 ? clamp(vis / wsum, 0.0, 1.0) : 1.0;
    c.bent = dot(bent, bent) > 1e-12 ? normalize(bent) : n;
    // GTSO: the cone whose cosine-weighted solid angle equals the visibility, sin^2 = V.
    c.aperture = acos(sqrt(1.0 - visibility));
    c.occluder = occ_w > 0.0 ? occ / occ_w : vec3(0.0);
    c.occluder_w = occ_w;
    return c;
}

// The share of a cone of half-angle `lobe` around `axis` inside the visibility cone (Oat and
// Sander 2007's smooth cap-cap overlap, over the lobe cap's solid angle); a ray (lobe 0): 1
// inside the cone, 0 outside, smoothed over 0.1 rad.
float cone_share(Cone c, vec3 axis, float lobe) {
    float theta = acos(clamp(dot(axis, c.bent), -1.0, 1.0));
    float av = c.aperture;
    if (lobe < 0.05) return 1.0 - smoothstep(av - 0.05, av + 0.05, theta);
    float lo = abs(av - lobe), hi = av + lobe;
    float overlap_min = 1.0 - cos(min(av, lobe));
    float overlap = theta <= lo ? overlap_min : theta >= hi ? 0.0 : overlap_min * smoothstep(0.0, 1.0, 1.0 - (theta - lo) / (hi - lo));
    return clamp(overlap / (1.0 - cos(lobe)), 0.0, 1.0);
}

// ---- METHOD 2: where the ray left the screen ---------------------------------------------------

float exit_visibility(vec3 o, vec3 d, out vec3 occluder) {
    occluder = vec3(0.0);
    float len = ray_length_in_front_of_near(o, d, ssr.max_distance);
    if (len <= 0.0) return 1.0;
    vec3 a = view_to_pixel(o), b = view_to_pixel(o + d * len);
    float s = screen_exit(a.xy, b.xy, frame.viewport.xy);
    // It never left the image: it ended at the near plane (toward the camera, into what the
    // frame cannot see behind it) or at max_distance. Screen space knows nothing: the sky.
    if (s >= 1.0) return 1.0;
    // The view point at the exit: 1/w is linear in screen space.
    float iw = mix(1.0 / a.z, 1.0 / b.z, s);
    float t = len * (s / b.z) / iw;
    vec3 r = o + d * t;
    ivec2 e = clamp(ivec2(floor(mix(a.xy, b.xy, s))), ivec2(0), g_size - 1);
    // The ray's own way to the exit, re-walked coarsely over layer 0: where it passed behind a
    // surface by less than HIDDEN_DEPTH of that surface's depth (more than the tracer's
    // thickness, so the tracer let it through), it went into the space the surface hides; a
    // solid object's hidden side is the object itself.
    for (int k = 1; k <= MARCH_STEPS; ++k) {
        float sk = s * float(k) / float(MARCH_STEPS + 1);
        vec2 px = mix(a.xy, b.xy, sk);
        ivec2 pi = clamp(ivec2(floor(px)), ivec2(0), g_size - 1);
        if (!covered(pi, 0)) continue;
        float scene_depth = texelFetch(u_linear_depth, ivec3(pi, 0), 0).r;
        float ray_depth_k = 1.0 / mix(1.0 / a.z, 1.0 / b.z, sk);
        if (ray_depth_k > scene_depth * (1.0 + 1e-3) + ssr.thickness && ray_depth_k < scene_depth * (1.0 + HIDDEN_DEPTH)) {
            occluder = texelFetch(u_lit, ivec3(pi, 0), 0).rgb;
            return 0.0;
        }
    }
    if (!covered(e, 0)) return 1.0;  // open sky at the border
    float ray_depth = -r.z;
    for (int layer = 0; layer < g_layers; ++layer) {
        if (!covered(e, layer)) break;
        float depth = texelFetch(u_linear_depth, ivec3(e, layer), 0).r;
        if (depth < ray_depth * (1.0 - 1e-3)) continue;  // in front of the ray: it passes behind
        vec3 sp = view_position(vec2(e) + 0.5, depth);
        vec3 n = normalize(texelFetch(u_normal, ivec3(e, layer), 0).xyz);
        occluder = texelFetch(u_lit, ivec3(e, layer), 0).rgb;
        float toward = -dot(d, n);
        float dist = dot(r - sp, n);
        if (toward <= 1e-4 || dist < 0.0) return 1.0;  // rising above the surface or beside it
        float t_plane = dist / toward;
        return 1.0 - exp(-t_plane / (EXIT_REACH * depth));
    }
    // Behind every layer at the exit: hidden space, where screen space saw only occluders.
    occluder = texelFetch(u_lit, ivec3(e, 0), 0).rgb;
    return 0.0;
}

// ---- per ray ------------------------------------------------------------------------------------

void main() {
    ivec3 id = ivec3(gl_GlobalInvocationID.xy, 0);
    if (id.x >= ssr.trace_width || id.y >= ssr.trace_height) return;
    g_size = ivec2(frame.viewport.xy);
    g_layers = int(frame.clip.z);
    vec4 smp0 = texelFetch(u_ray_sample, ivec3(id.xy, 0), 0);
    bool any_unresolved = false;
    for (int r = 0; r < u_rays; ++r) {
        vec4 hit = texelFetch(u_ray_hit, ivec3(id.xy, r), 0);
        float w = texelFetch(u_ray_sample, ivec3(id.xy, r), 0).x;
        if (smp0.w > 0.5 && w > 0.0 && !(hit.z > 0.5 && hit.w >= 1.0)) any_unresolved = true;
    }
    if (!any_unresolved) {
        for (int r = 0; r < u_rays; ++r) imageStore(o_radiance, ivec3(id.xy, r), vec4(0.0, 0.0, 0.0, -2.0));
        return;
    }
    ivec2 p = min(id.xy * ssr.downscale + ssr.downscale / 2, g_size - 1);
    GSample g = gbuffer_decode(texelFetch(u_albedo, ivec3(p, 0), 0), texelFetch(u_normal, ivec3(p, 0), 0),
                               texelFetch(u_material, ivec3(p, 0), 0));
    vec3 pos = view_position(vec2(p) + 0.5, texelFetch(u_linear_depth, ivec3(p, 0), 0).r);
    vec3 origin = pos + g.normal * (ssr.origin_bias * -pos.z);  // as lib/ray_generation.glsl
    vec3 v = normalize(-pos);
    float alpha = g.roughness * g.roughness;
    float n_dot_v = clamp(dot(g.normal, v), 0.0, 1.0);
#if METHOD == 1
    Cone cone = horizon_cone(p, pos, g.normal);
#endif
    uint unresolved = 0u, occluded = 0u;
    for (int r = 0; r < u_rays; ++r) {
        ivec3 rid = ivec3(id.xy, r);
        vec4 hit = texelFetch(u_ray_hit, rid, 0);
        float w = texelFetch(u_ray_sample, rid, 0).x;
        if (!(smp0.w > 0.5 && w > 0.0) || (hit.z > 0.5 && hit.w >= 1.0)) {
            imageStore(o_radiance, rid, vec4(0.0, 0.0, 0.0, -2.0));
            continue;
        }
        vec3 d = normalize(texelFetch(u_ray_direction, rid, 0).xyz);
        vec3 c;
        float vis;
#if FADED_HITS
        if (hit.z > 0.5) {
            // A faded hit knows where it went: the surface it hit blocks the ray.
            ++unresolved;
            ++occluded;
            ivec3 hp = ivec3(clamp(ivec2(hit.xy), ivec2(0), g_size - 1), int(hit.z) - 1);
            imageStore(o_radiance, rid, vec4(texelFetch(u_lit, hp, 0).rgb, -1.0));
            continue;
        }
#endif
#if LOBE
        // The lobe the single mirror ray stands for (glossy_environment_lobe's directions).
        bool mirror = alpha < 1e-4;
        mat3 tbn = frame_from_normal(g.normal);
        vec3 v_local = transpose(tbn) * v;
#if METHOD == 1
        vec3 env = vec3(0.0);
        float total = 0.0;
        for (int i = 0; i < (mirror ? 1 : LOBE_SAMPLES); ++i) {
            vec2 u2 = hammersley(uint(i), uint(LOBE_SAMPLES)) + vec2(0.5 / float(LOBE_SAMPLES), 0.0);
            BrdfSample bs = sample_reflection(v_local, alpha, SAMPLING_VNDF, fract(u2));
            vec3 l = mirror ? d : tbn * bs.l;
            float wl = mirror ? 1.0 : bs.weight;
            if (wl <= 0.0) continue;
            env += wl * env_view(l);
            total += wl;
        }
        env = total > 0.0 ? env / total : env_view(d);
        vis = cone_share(cone, d, mirror ? 0.0 : cone_angle(g.roughness, n_dot_v));
        c = mix(cone.occluder, env, vis);
#else
        vec3 sum = vec3(0.0);
        float total = 0.0, vsum = 0.0;
        for (int i = 0; i < (mirror ? 1 : LOBE_SAMPLES); ++i) {
            vec2 u2 = hammersley(uint(i), uint(LOBE_SAMPLES)) + vec2(0.5 / float(LOBE_SAMPLES), 0.0);
            BrdfSample bs = sample_reflection(v_local, alpha, SAMPLING_VNDF, fract(u2));
            vec3 l = mirror ? d : tbn * bs.l;
            float wl = mirror ? 1.0 : bs.weight;
            if (wl <= 0.0) continue;
            vec3 occ;
            float vl = exit_visibility(origin, l, occ);
            sum += wl * mix(occ, env_view(l), vl);
            vsum += wl * vl;
            total += wl;
        }
        c = total > 0.0 ? sum / total : env_view(d);
        vis = total > 0.0 ? vsum / total : 1.0;
#endif
#else
#if METHOD == 1
        vis = cone_share(cone, d, 0.0);
        c = mix(cone.occluder, env_view(d), vis);
#else
        vec3 occ;
        vis = exit_visibility(origin, d, occ);
        c = mix(occ, env_view(d), vis);
#endif
#endif
        ++unresolved;
        if (vis < 0.5) ++occluded;
        imageStore(o_radiance, rid, vec4(c, -1.0));
    }
    if (unresolved > 0u) atomicAdd(counters.unresolved, unresolved);
    if (occluded > 0u) atomicAdd(counters.occluded, occluded);
}
