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
//     with cos(aperture) = sqrt(1 - visibility); the lobe's visible share SO is the solid angle
//     that cone shares with the lobe's cone around the mirror direction (half-angle
//     lib/cone_angle.glsl's; the cap-cap overlap of Oat and Sander 2007, "Ambient aperture
//     lighting"), over the lobe's. A miss of the stochastic resolve takes the occluded share
//     that the pixel's resolved rays do not already account for (see main); the lobe of cone
//     and blur_mips, SO. The occluder: the samples that set the horizons, weighted by the angle
//     each blocks.
//   METHOD 2, "exit": what the frame knows of where the ray went.
//     (a) Its way to the screen's edge, re-walked in MARCH_STEPS samples: where it is farther
//         than every surface of the enclosure cell around it (stages 0-1: the farthest layer-0
//         depth of a cell and its 8 neighbours, infinitely far if any of their pixels shows
//         the background), it is behind a closed region -- the background there continues
//         behind whatever covers the ray -- and is blocked (V = 0). A ray merely behind the
//         nearest surface is not: it may pass behind an object (an open scene's spheres).
//     (b) At its exit pixel, the first surface of the deep G-buffer's layers at or behind the
//         ray: none (open sky at the border) leaves V = 1; a surface whose plane the ray runs
//         toward (n . d < 0) is taken to continue beyond the screen: the ray meets the plane
//         after t, and V = 1 - exp(-t / (EXIT_REACH * depth)), a confidence that shrinks with
//         how far the plane must be extrapolated relative to its distance to the camera; a
//         plane the ray rises away from (a floor) does not block it; a ray behind every layer
//         there went into hidden space (V = 0).
//     A ray that ends on screen (at max_distance, or the near plane) without (a): V = 1.
//   Both: a faded hit whose surface faces the ray knows where it went: V = 0 and its own lit
//   colour (measured on hall: right to 6 % where the environment it faded toward was 139 % off).
// The occluder's radiance, where it is not a hit: the ambient term of the surface found
// (ambient x albedo), not its lit colour. What blocks a reflection ray that screen space missed
// is the side of a surface the camera does not see (undersides, backs), which the direct light
// mostly does not reach either; measured on hall at roughness 0.2 against the lit colour and
// the mean of both (docs/occlusion.md).
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
#include "../lib/input_fetch.glsl"

// 0: the farthest surface of each enclosure cell; 1: of each cell and its 8 neighbours;
// 2: the rays; 3: the counters set to zero (before stage 2, in each run of the chain).
#ifndef STAGE
#define STAGE 2
#endif

#ifndef METHOD
#define METHOD 2
#endif
#ifndef LOBE
#define LOBE 0
#endif

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

// Every stage declares the inputs, by name; with FETCH_BY_IMAGE (lib/input_fetch.glsl) the float
// inputs are images (passes/specular_occlusion.cpp).
INPUT_ARRAY(u_linear_depth, TEXTURE_LINEAR_DEPTH, IMAGE_LINEAR_DEPTH, r32f);
INPUT_ARRAY(u_normal, TEXTURE_GBUFFER_NORMAL, IMAGE_GBUFFER_NORMAL, rgba16f);
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;
INPUT_ARRAY(u_lit, TEXTURE_LIT, IMAGE_LIT, rgba16f);
INPUT_ARRAY(u_ray_hit, TEXTURE_RAYS_HIT, IMAGE_RAYS_HIT, rgba32f);
INPUT_ARRAY(u_ray_sample, TEXTURE_RAYS_SAMPLE, IMAGE_RAYS_SAMPLE, rgba32f);
INPUT_ARRAY(u_ray_direction, TEXTURE_RAYS_DIRECTION, IMAGE_RAYS_DIRECTION, rgba32f);
layout(binding = TEXTURE_GBUFFER_ALBEDO) uniform sampler2DArray u_albedo;
#if METHOD == 2
INPUT_2D(u_cells, TEXTURE_OCCLUSION_ENCLOSURE, IMAGE_OCCLUSION_ENCLOSURE, r32f);  // stage 1's output
#endif
layout(std430, binding = BUFFER_OCCLUSION_COUNTERS) buffer OcclusionCounters {
    uint unresolved;
    uint occluded;
} counters;

layout(location = 0) uniform int u_rays;  // rays per trace pixel (layers of rays.*)
const int CELL_DIVISOR = 16;
// The side of an enclosure cell, pixels (= SpecularOcclusionPass::cell).
int cell_size() {
    return max(4, int(frame.viewport.y) / CELL_DIVISOR);
}

const int SLICES = 4;         // horizon: screen slices (GTAO's directions)
const int STEPS = 8;          // horizon: depth samples per side of a slice
const float RADIUS = 0.25;    // horizon: search radius, fraction of the image height
const float EXIT_REACH = 1.0; // exit: extrapolation scale, in units of the surface's view depth
const int LOBE_SAMPLES = 16;  // as lib/glossy_common.glsl's ENV_LOBE_SAMPLES
const int MARCH_STEPS = 8;   // exit: samples of the ray's way to the screen's edge

ivec2 g_size;
int g_layers;
// Uniform values the per-ray walks read, read once at the start of main (llvmpipe
// reads a uniform-block value lane by lane, with a bounds check per lane, inside loops and
// branches; reading them there made the exit walk 5x slower).
mat4 g_proj;
mat3 g_to_world;
vec4 g_viewport;
float g_near, g_thickness, g_max_distance;
vec3 g_ambient;
float g_inv_cell;

void read_uniforms() {
    g_size = ivec2(frame.viewport.xy);
    g_layers = int(frame.clip.z);
    g_proj = frame.proj;
    g_to_world = mat3(frame.inv_view);
    g_viewport = frame.viewport;
    g_near = frame.clip.x;
    g_thickness = ssr.thickness;
    g_max_distance = ssr.max_distance;
    g_ambient = frame.ambient.rgb;
    g_inv_cell = 1.0 / float(max(4, int(frame.viewport.y) / CELL_DIVISOR));
}

// lib/screen_ray.glsl's view_to_pixel and lib/depth_convention.glsl's view_position, from the
// values above.
vec3 pixel_of(vec3 p) {
    vec4 c = g_proj * vec4(p, 1.0);
    return vec3((c.xy / c.w * 0.5 + 0.5) * g_viewport.xy, c.w);
}

vec3 view_point(vec2 pixel, float z) {
    vec2 ndc = pixel * g_viewport.zw * 2.0 - 1.0;
    return vec3((ndc + vec2(g_proj[2][0], g_proj[2][1])) * z / vec2(g_proj[0][0], g_proj[1][1]), -z);
}

vec3 env_view(vec3 d) {
    return environment_radiance(normalize(g_to_world * d));
}

bool covered(ivec2 p, int layer) {
    return texelFetch(u_material, ivec3(p, layer), 0).g > 0.5;
}

// The radiance assumed for the unseen side of the surface at pixel p of `layer` (see the top).
vec3 occluder_radiance(ivec2 p, int layer) {
    return g_ambient * texelFetch(u_albedo, ivec3(p, layer), 0).rgb;
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
    float radius_px = RADIUS * g_viewport.y;
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
        // The slice: the plane through the camera and the screen line through p along dir2
        // (it holds v and the view-space direction of that line at p's depth); every sample
        // below lies in it.
        vec3 line = normalize(vec3(dir2.x / g_proj[0][0], dir2.y / g_proj[1][1], 0.0));
        vec3 u = normalize(line - dot(line, v) * v);
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
                vec3 sp = view_point(vec2(qi) + 0.5, FETCH(u_linear_depth, ivec3(qi, 0)).r);
                vec3 w = sp - pos;
                float c = dot(w, v) * inversesqrt(max(dot(w, w), 1e-12));
                if (c > best) {
                    best = c;
                    best_c = occluder_radiance(qi, 0);
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
        bent += np_len * (v * cos(b) - v * cos(n_ang) + u * (sin(b) - sin(n_ang)));
    }
    Cone c;
    float visibility = wsum > 0.0 ? clamp(vis / wsum, 0.0, 1.0) : 1.0;
    // The mid-horizon directions summed over slices lean toward v even with no occluder (each
    // slice holds n's projection, not n): their unoccluded sum is subtracted above and n put in
    // its place, so that an open surface's bent normal is its normal.
    c.bent = normalize(n * wsum + bent);
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
#if METHOD == 2

float exit_visibility(vec3 o, vec3 d, out vec3 occluder) {
    occluder = vec3(0.0);
    // The ray's length in front of the near plane (lib/screen_ray.glsl), at most max_distance.
    float len = g_max_distance;
    if (o.z + d.z * len > -g_near) len = (-g_near - o.z) / d.z * 0.999;
    if (len <= 0.0) return 1.0;
    vec3 a = pixel_of(o), b = pixel_of(o + d * len);
    float s = screen_exit(a.xy, b.xy, g_viewport.xy);
    // (a) The ray's way to the edge (the top of the file).
    for (int k = 1; k <= MARCH_STEPS; ++k) {
        float sk = s * float(k) / float(MARCH_STEPS + 1);
        vec2 px = mix(a.xy, b.xy, sk);
        ivec2 pi = clamp(ivec2(floor(px)), ivec2(0), g_size - 1);
        float ray_depth_k = 1.0 / mix(1.0 / a.z, 1.0 / b.z, sk);
        // (a float product: x86 has no vector integer division, so llvmpipe divides lane by lane)
        float cell_depth = FETCH(u_cells, ivec2((vec2(pi) + 0.5) * g_inv_cell)).r;
        if (ray_depth_k > cell_depth * (1.0 + 1e-3) + g_thickness) {
            // Behind every surface of a closed block: blocked.
            occluder = occluder_radiance(pi, 0);
            return 0.0;
        }
    }
    // It never left the image: it ended at the near plane (toward the camera, into what the
    // frame cannot see behind it) or at max_distance, in front of everything. The sky.
    if (s >= 1.0) return 1.0;
    // (b) The view point at the exit: 1/w is linear in screen space.
    float iw = mix(1.0 / a.z, 1.0 / b.z, s);
    float t = len * (s / b.z) / iw;
    vec3 r = o + d * t;
    ivec2 e = clamp(ivec2(floor(mix(a.xy, b.xy, s))), ivec2(0), g_size - 1);
    if (!covered(e, 0)) return 1.0;  // open sky at the border
    float ray_depth = -r.z;
    for (int layer = 0; layer < g_layers; ++layer) {
        if (!covered(e, layer)) break;
        float depth = FETCH(u_linear_depth, ivec3(e, layer)).r;
        if (depth < ray_depth * (1.0 - 1e-3)) continue;  // in front of the ray: it passes behind
        vec3 sp = view_point(vec2(e) + 0.5, depth);
        vec3 n = normalize(FETCH(u_normal, ivec3(e, layer)).xyz);
        occluder = occluder_radiance(e, layer);
        float toward = -dot(d, n);
        float dist = dot(r - sp, n);
        if (toward <= 1e-4 || dist < 0.0) return 1.0;  // rising above the surface or beside it
        float t_plane = dist / toward;
        return 1.0 - exp(-t_plane / (EXIT_REACH * depth));
    }
    // Behind every layer at the exit: hidden space, where screen space saw only occluders.
    occluder = occluder_radiance(e, 0);
    return 0.0;
}
#endif

#if STAGE == 0
// ---- stage 0: enclosure cells -----------------------------------------------------------------
// The farthest layer-0 surface of each cell, or 1e30 where it shows background (seed 002's
// Hi-Z max, but with the sky counted as infinitely far, which the tracer's pyramid leaves out).
// One work group per cell: its 64 invocations stride over the cell's pixels and reduce their
// maxima in shared memory (the same value in any order). One invocation per cell, looping over
// its cell^2 pixels, left a GPU with a few thousand busy lanes: 1.16 ms at 1920x1080 on an H200.
layout(binding = IMAGE_OCCLUSION_CELLS, r32f) writeonly uniform image2D o_cells;
shared float s_far[64];

void main() {
    ivec2 c = ivec2(gl_WorkGroupID.xy);
    ivec2 t = ivec2(gl_LocalInvocationID.xy);
    ivec2 size = ivec2(frame.viewport.xy);
    int cell = cell_size();
    ivec2 lo = c * cell, hi = min(lo + cell, size);
    float far_depth = 0.0;
    for (int y = lo.y + t.y; y < hi.y; y += 8)
        for (int x = lo.x + t.x; x < hi.x; x += 8) {
            ivec3 p = ivec3(x, y, 0);
            far_depth = max(far_depth, texelFetch(u_material, p, 0).g > 0.5 ? FETCH(u_linear_depth, p).r : 1e30);
        }
    uint i = gl_LocalInvocationIndex;
    s_far[i] = far_depth;
    barrier();
    for (uint half_count = 32u; half_count > 0u; half_count >>= 1u) {
        if (i < half_count) s_far[i] = max(s_far[i], s_far[i + half_count]);
        barrier();
    }
    if (i == 0u) imageStore(o_cells, c, vec4(s_far[0]));
}
#elif STAGE == 1
// ---- stage 1: a cell and its 8 neighbours ------------------------------------------------------
// A ray farther than every surface of a closed region is behind all of it: the region's
// background continues behind whatever covers the ray. The region is a cell and its
// neighbours, so that an object filling one cell does not close it.
layout(binding = IMAGE_OCCLUSION_ENCLOSURE, r32f) writeonly uniform image2D o_enclosure;
layout(binding = IMAGE_OCCLUSION_CELLS, r32f) readonly uniform image2D u_cell_depth;

void main() {
    ivec2 c = ivec2(gl_GlobalInvocationID.xy);
    ivec2 n = imageSize(o_enclosure);
    if (any(greaterThanEqual(c, n))) return;
    float far_depth = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x)
            far_depth = max(far_depth, imageLoad(u_cell_depth, clamp(c + ivec2(x, y), ivec2(0), n - 1)).r);
    imageStore(o_enclosure, c, vec4(far_depth));
}
#elif STAGE == 3
// ---- stage 3: the counters set to zero ----------------------------------------------------------
// By a shader write, ordered after every earlier dispatch's atomics on the device's own timeline
// (the untimed first-use run's among them), not by a buffer update from the host.
void main() {
    if (gl_GlobalInvocationID.xy == uvec2(0u)) {
        counters.unresolved = 0u;
        counters.occluded = 0u;
    }
}
#else
// ---- stage 2: per ray ---------------------------------------------------------------------------

layout(binding = IMAGE_RAYS_RADIANCE, rgba32f) writeonly uniform image2DArray o_radiance;
void main() {
    read_uniforms();  // before any control flow
    ivec3 id = ivec3(gl_GlobalInvocationID.xy, 0);
    if (id.x >= ssr.trace_width || id.y >= ssr.trace_height) return;
    vec4 smp0 = FETCH(u_ray_sample, ivec3(id.xy, 0));
    bool any_unresolved = false;
    float w_hit = 0.0, w_all = 0.0;  // horizon: the share of the pixel's rays screen space resolved
    for (int r = 0; r < u_rays; ++r) {
        vec4 hit = FETCH(u_ray_hit, ivec3(id.xy, r));
        float w = FETCH(u_ray_sample, ivec3(id.xy, r)).x;
        bool ray = smp0.w > 0.5 && w > 0.0;
        if (ray && !(hit.z > 0.5 && hit.w >= 1.0)) any_unresolved = true;
        w_all += ray ? w : 0.0;
        w_hit += ray && hit.z > 0.5 ? w * hit.w : 0.0;
    }
    if (!any_unresolved) {
        for (int r = 0; r < u_rays; ++r) imageStore(o_radiance, ivec3(id.xy, r), vec4(0.0, 0.0, 0.0, -2.0));
        return;
    }
    ivec2 p = min(id.xy * ssr.downscale + ssr.downscale / 2, g_size - 1);
    GSample g = gbuffer_decode(texelFetch(u_albedo, ivec3(p, 0), 0), FETCH(u_normal, ivec3(p, 0)),
                               texelFetch(u_material, ivec3(p, 0), 0));
    vec3 pos = view_position(vec2(p) + 0.5, FETCH(u_linear_depth, ivec3(p, 0)).r);
    vec3 origin = pos + g.normal * (ssr.origin_bias * -pos.z);  // as lib/ray_generation.glsl
    vec3 v = normalize(-pos);
    float alpha = g.roughness * g.roughness;
    float n_dot_v = clamp(dot(g.normal, v), 0.0, 1.0);
#if METHOD == 1
    Cone cone = horizon_cone(p, pos, g.normal);
    // GTSO's visible share of the whole lobe (around the mirror direction); the rays screen
    // space resolved already stand for part of the occluded share, so the misses take only the
    // rest of it: V_miss = 1 - max(0, (1 - SO) - h) / (1 - h), h the resolved share. (Applying
    // SO to every miss counts the occlusion screen space found twice.)
    bool mirror_lobe = alpha < 1e-4 || ssr.sampling == SAMPLING_MIRROR;
    float so = cone_share(cone, reflect(-v, g.normal), mirror_lobe ? 0.0 : cone_angle(g.roughness, n_dot_v));
    float h = LOBE != 0 ? 0.0 : (w_all > 0.0 ? w_hit / w_all : 0.0);
    float v_miss = h < 0.999 ? 1.0 - max(0.0, (1.0 - so) - h) / (1.0 - h) : 1.0;
#endif
    uint unresolved = 0u, occluded = 0u;
    for (int r = 0; r < u_rays; ++r) {
        ivec3 rid = ivec3(id.xy, r);
        vec4 hit = FETCH(u_ray_hit, rid);
        float w = FETCH(u_ray_sample, rid).x;
        if (!(smp0.w > 0.5 && w > 0.0) || (hit.z > 0.5 && hit.w >= 1.0)) {
            imageStore(o_radiance, rid, vec4(0.0, 0.0, 0.0, -2.0));
            continue;
        }
        vec3 d = normalize(FETCH(u_ray_direction, rid).xyz);
        vec3 c;
        float vis;
        ivec3 hp = ivec3(clamp(ivec2(hit.xy), ivec2(0), g_size - 1), max(int(hit.z) - 1, 0));
        // A faded hit that faces the ray (the first of lib/screen_confidence.glsl's tests: a
        // back-facing "hit", e.g. a floor finding itself near the border, passed behind or
        // along a surface) knows where it went: the surface it hit blocks the ray.
        if (hit.z > 0.5 && dot(FETCH(u_normal, hp).xyz, d) < 0.0) {
            ++unresolved;
            ++occluded;
            imageStore(o_radiance, rid, vec4(FETCH(u_lit, hp).rgb, -1.0));
            continue;
        }
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
        vis = so;
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
        vis = v_miss;
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
#endif
