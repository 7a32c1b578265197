#version 450 core
// trace_linear: McGuire & Mara's perspective-correct DDA in homogeneous screen space
// (JCGT 3(4), 2014; seed 000, 2.3.1), over every G-buffer layer. The ray steps `stride`
// pixels along its major screen axis while its view depth and 1/w are interpolated
// linearly (perspective-correct); at each step it hits layer k when the depth range it
// covers over the step overlaps [depth_k, depth_k + thickness]. One invocation per
// (trace pixel, ray).
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/ssr_settings.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/brdf.glsl"
#include "../lib/random.glsl"
#include "../lib/ggx_sampling.glsl"
#include "../lib/ray_generation.glsl"
#include "../lib/screen_ray.glsl"
#include "../lib/trace_common.glsl"
#include "../lib/input_fetch.glsl"
#include "../lib/screen_sight.glsl"
#if RAY_LIST
#include "../lib/ray_list.glsl"
#endif

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

// By name (trace_pass.cpp); with FETCH_BY_IMAGE the float inputs are images.
INPUT_ARRAY(u_linear_depth, TEXTURE_LINEAR_DEPTH, IMAGE_LINEAR_DEPTH, r32f);
layout(binding = TEXTURE_GBUFFER_ALBEDO) uniform sampler2DArray u_albedo;
INPUT_ARRAY(u_normal, TEXTURE_GBUFFER_NORMAL, IMAGE_GBUFFER_NORMAL, rgba16f);
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;

float g_fetches = 0.0;
// Settings the march reads on every step, read once at the start of main, before its first
// `return`: llvmpipe (Mesa 22.3) reads a uniform-block value lane by lane, with a
// bounds check per lane, wherever lane 0 may be masked off (inside a loop, an if, or after a return).
int g_max_steps, g_thickness_mode, g_refine_steps, g_layers;
float g_stride, g_thickness, g_thickness_scale, g_far;
// The layers that hold a surface somewhere (frame.stats["layers_used"] with
// Settings.skip, else Settings.layers), set by trace_pass.cpp: the walk never fetches a layer
// empty everywhere, where it would only find the empty layer that ends it.
uniform int u_layers_used;
// 1 when exactly one layer is in use (trace_pass.cpp): the layer walk is a single test.
#ifndef TRACE_ONE_LAYER
#define TRACE_ONE_LAYER 0
#endif
// 1 when an exact fallback takes the rays screen space cannot vouch for (trace_pass.cpp:
// fallback "bvh" with fallback_confidence): the march ends as a miss where the ray leaves the
// G-buffer's sight (lib/screen_sight.glsl), at one more depth fetch per step.
#ifndef STOP_UNSEEN
#define STOP_UNSEEN 0
#endif
Sight g_sight;

float layer_depth(ivec2 pixel, int layer) {
    g_fetches += 1.0;
    return FETCH(u_linear_depth, ivec3(pixel, layer)).r;
}

// The first layer, front to back, whose slab [d, d + thick] the ray's depth range [lo, hi]
// at `pixel` overlaps; -1 for none. Layers are depth-sorted per pixel, so the walk stops at
// the first surface the ray is in front of, or at an empty layer: a ray in front of every
// surface costs one fetch whatever the layer count (the thesis fetches every layer).
// The loop is left by `break`, and for one layer in use (TRACE_ONE_LAYER, trace_pass.cpp) there
// is no loop: `return`s inside a loop, and a loop of one iteration, cost llvmpipe.
// With STOP_UNSEEN, `side` is the pixel beside `pixel` the ray passes nearer to, for g_sight.
int layer_hit(ivec2 pixel, ivec2 side, float lo, float hi, float thick, out float surface) {
#if TRACE_ONE_LAYER
    float d = layer_depth(pixel, 0);
    surface = d;
#if STOP_UNSEEN
    sight_step(g_sight, lo, hi, d, d < g_far && lo > d + thick, layer_depth(side, 0), thick);
#endif
    // an empty layer (d >= far) holds no surface here
    return d >= g_far || hi < d || lo > d + thick ? -1 : 0;
#else
    surface = 0.0;
    int found = -1;
    int k = 0;
    float d = g_far, d_before = g_far;
    for (; k < g_layers; ++k) {
        d_before = d;
        d = layer_depth(pixel, k);
        if (d >= g_far) break;  // empty layer: no surface here or behind
        if (hi < d) break;
        if (lo <= d + thick) {
            surface = d;
            found = k;
            break;
        }
    }
#if STOP_UNSEEN
    // Behind every layer kept, or in the gap behind a layer that faces the camera (inside its
    // object; the normal is fetched only then). The side pixel at the layer the walk stopped at.
    bool behind = found < 0 && k > 0 &&
                  (k == g_layers || dot(FETCH(u_normal, ivec3(pixel, k - 1)).xyz, -view_position(vec2(pixel) + 0.5, d_before)) > 0.0);
    int at = min(k, g_layers - 1);
    sight_step(g_sight, lo, hi, k == g_layers ? g_far : d, behind, layer_depth(side, at), thick);
#endif
    return found;
#endif
}

struct LinearHit {
    bool hit;
    vec2 pixel;   // exact crossing, GL pixel coordinates
    int layer;
    float depth;  // positive view depth of the surface hit
};

LinearHit trace_linear(ReflectionRay ray, float jitter_u) {
    LinearHit result;
    result.hit = false;
    float len = ray_length_in_front_of_near(ray.origin, ray.dir, ssr.max_distance);
    vec3 end = ray.origin + ray.dir * len;
    vec4 h0 = frame.proj * vec4(ray.origin, 1.0);
    vec4 h1 = frame.proj * vec4(end, 1.0);
    // z/w and 1/w are affine in screen space: interpolating them is perspective-correct.
    float k0 = 1.0 / h0.w, k1 = 1.0 / h1.w;
    float qz0 = ray.origin.z * k0, qz1 = end.z * k1;
    vec2 p0 = (h0.xy * k0 * 0.5 + 0.5) * frame.viewport.xy;
    vec2 p1 = (h1.xy * k1 * 0.5 + 0.5) * frame.viewport.xy;
    float t_screen = screen_exit(p0, p1, frame.viewport.xy);  // clip the segment to the image
    p1 = mix(p0, p1, t_screen);
    k1 = mix(k0, k1, t_screen);
    qz1 = mix(qz0, qz1, t_screen);
    vec2 delta = p1 - p0;
    if (dot(delta, delta) < 1e-4) return result;  // the ray covers no screen distance

    bool permute = abs(delta.y) > abs(delta.x);  // march along the major axis (x after the swap)
    if (permute) {
        delta = delta.yx;
        p0 = p0.yx;
        p1 = p1.yx;
    }
    float step_dir = sign(delta.x);
    float inv_dx = step_dir / delta.x;
    vec2 dp = vec2(step_dir, delta.y * inv_dx) * g_stride;
    float dqz = (qz1 - qz0) * inv_dx * g_stride;
    float dk = (k1 - k0) * inv_dx * g_stride;

    // The ray's view depth at parameter s (in steps from p0): z(s) = -(qz0 + dqz s) / (k0 + dk s).
    // Each step's depth range runs on from where the previous one ended, starting where the
    // ray leaves the origin pixel, so no stretch of the ray goes untested; the jitter only
    // moves which pixels are sampled: a random shift of up to stride - 1 pixels (McGuire &
    // Mara's per-pixel jitter, which trades a long stride's banding for noise).
    float s_prev = 0.5 / g_stride;
    float z_prev = -(qz0 + dqz * s_prev) / (k0 + dk * s_prev);
    float start = ssr.jitter * jitter_u * (1.0 - 1.0 / g_stride);
    vec2 p = p0 + dp * start;
    float qz = qz0 + dqz * start, k = k0 + dk * start;
    float end_x = p1.x * step_dir;
    ivec2 last_pixel = ivec2(frame.viewport.xy) - 1;

    // The march leaves its loop by `break` and refines a hit after it (a `return`
    // inside the loop costs llvmpipe).
    int layer = -1;
    float surface = 0.0, thick = 0.0;
    ivec2 pixel = ivec2(0);
    for (int i = 0; i < g_max_steps; ++i) {
        p += dp;
        qz += dqz;
        k += dk;
        if (p.x * step_dir > end_x) break;
        // Half a step on, but not past the segment's end: beyond it 1/w (k) of a ray
        // running toward its vanishing point can reach 0 or less, and the step's depth range
        // then spanned everything in front of the origin, a false hit far off the ray.
        float half_step = clamp((end_x - p.x * step_dir) / g_stride, 0.0, 0.5);
        float z_next = -(qz + half_step * dqz) / (k + half_step * dk);
        float lo = min(z_prev, z_next), hi = max(z_prev, z_next);
        z_prev = z_next;
        thick = g_thickness_mode == THICKNESS_MODE_RAY_STEP ? max(g_thickness, g_thickness_scale * (hi - lo)) : g_thickness;
        pixel = clamp(ivec2(floor(permute ? p.yx : p)), ivec2(0), last_pixel);
#if STOP_UNSEEN
        // The other pixel of the two the ray's half-pixel-wide footprint straddles across the march.
        vec2 ps = vec2(p.x, p.y + (fract(p.y) < 0.5 ? -0.5 : 0.5));
        ivec2 side = clamp(ivec2(floor(permute ? ps.yx : ps)), ivec2(0), last_pixel);
#else
        ivec2 side = pixel;
#endif
        layer = layer_hit(pixel, side, lo, hi, thick, surface);
        if (layer >= 0 || (STOP_UNSEEN != 0 && g_sight.lost)) break;
    }
    if (STOP_UNSEEN != 0 && g_sight.lost) layer = -1;
    if (layer >= 0) {
        // Binary search between the previous step and this one (seed 001 3.4, seed 002
        // Fig. 4.5): keeps the hit on the near side of thin features a long stride skipped.
        float s_lo = -1.0, s_hi = 0.0;
        for (int b = 0; b < g_refine_steps; ++b) {
            float mid = 0.5 * (s_lo + s_hi);
            vec2 pm = p + dp * mid;
            ivec2 pix_m = clamp(ivec2(floor(permute ? pm.yx : pm)), ivec2(0), last_pixel);
            float zm = -(qz + dqz * mid) / (k + dk * mid);
            float dm = layer_depth(pix_m, layer);
            if (zm >= dm && zm <= dm + thick) {
                s_hi = mid;
                pixel = pix_m;
                surface = dm;
            } else {
                s_lo = mid;
            }
        }
        float s_base = g_refine_steps > 0 ? s_hi : 0.0;
        // The exact crossing near this position: where the ray's depth equals the surface's,
        // z(s) = -(qz + dqz s) / (k + dk s) = surface.
        float denom = dqz + surface * dk;
        float s = abs(denom) > 1e-20 ? -(qz + surface * k) / denom : s_base;
        s = clamp(s, s_base - 0.5, s_base + 0.5);
        vec2 hp = p + dp * s;
        hp = permute ? hp.yx : hp;
        result.hit = true;
        // Stay inside the pixel whose surface was hit, off its edges too: a hit exactly on
        // the lower edge read back as the neighbouring row in hit_uv's top-down convention.
        result.pixel = clamp(hp, vec2(pixel) + 0.001, vec2(pixel) + 0.999);
        result.layer = layer;
        result.depth = surface;
    }
    return result;
}

void main() {
    g_max_steps = ssr.max_steps;
    g_thickness_mode = ssr.thickness_mode;
    g_refine_steps = ssr.refine_steps;
    g_stride = ssr.stride;
    g_thickness = ssr.thickness;
    g_thickness_scale = ssr.thickness_scale;
    g_far = frame.clip.y;
    g_layers = min(ssr.layers, u_layers_used);
#if RAY_LIST
    // Only the pixels the classify pass listed; it wrote the others' outputs.
    ivec3 id;
    if (!ray_list_entry(id)) return;
#else
    ivec3 id = ivec3(gl_GlobalInvocationID);  // (trace pixel, ray index)
    if (id.x >= ssr.trace_width || id.y >= ssr.trace_height) return;
#endif
    ivec2 p = origin_pixel(id.xy);
    GSample g = gbuffer_decode(texelFetch(u_albedo, ivec3(p, 0), 0), FETCH(u_normal, ivec3(p, 0)),
                               texelFetch(u_material, ivec3(p, 0), 0));
#if defined(EXTRA_RAYS) && EXTRA_RAYS
    // The variance-guided second pass (variance_rays.comp listed this pixel): only the
    // rays adaptive_rays left out, drawn exactly as a full trace draws ray id.z.
    if (id.z < adaptive_ray_count(g.roughness)) return;
#endif
    vec3 pos = view_position(vec2(p) + 0.5, FETCH(u_linear_depth, ivec3(p, 0)).r);
    ReflectionRay ray = generate_ray(g, pos, id.xy, id.z);
#if STOP_UNSEEN
    // From the exact surface point, as the fallback retraces the ray and the confidence test
    // checks its hit (passes/trace_bvh.comp), not lifted by origin_bias (lib/hiz_walk.glsl's
    // slot_ray says why).
    ray.origin = pos;
#endif
    vec4 hit = vec4(0.0);
    g_sight = sight_start();
    if (ray.weight > 0.0) {
        float jitter_u = unit_float(pcg_hash(uint(id.x) * 9781u + uint(id.y) * 6271u + uint(id.z) * 26699u + ssr.seed));
        LinearHit h = trace_linear(ray, jitter_u);
        // A ray lost from sight: a miss marked as the confidence test marks the hits it rejects
        // (rays.hit (0, 0, 0, -1)), for the fallback to retrace.
        if (g_sight.lost) hit = vec4(0.0, 0.0, 0.0, -1.0);
        if (h.hit) {
            vec3 hit_view = view_position(h.pixel, h.depth);
            hit = vec4(h.pixel, float(h.layer + 1), hit_fade(h.pixel, ray.origin, ray.dir, hit_view));
        }
    }
    store_ray(id, ray, is_reflective(g), hit, g_fetches);
#if RAY_LIST && defined(EXTRA_RAYS) && EXTRA_RAYS
    ray_list_count(ray.weight, g_fetches);  // the second trace's counters (trace_hiz.comp says why only it)
#endif
}
