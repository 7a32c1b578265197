#version 450 core
// fallback_probes: reflection probes, seed 004's local cube maps between screen space and the
// global environment (cpp/passes/fallback_probes.h).
//   STAGE 0, capture: one invocation per cube-map texel (x, y, 6 * probe + face): the ray from
//            the probe's centre through the texel, traced against the triangles and shaded by
//            lib/trace_shade.glsl as seen from the probe (viewer = the ray's origin); rgb the
//            lit colour, a the hit distance (-1: the environment).
//   STAGE 1, lookup: one invocation per (trace pixel, ray) after a screen-space tracer; a ray
//            screen space did not resolve takes the nearest probe to its origin,
//            parallax-corrected by box projection on the scene bounds refined by the probe's
//            distances, at the mip level whose texel covers its roughness cone.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/ssr_settings.glsl"
#include "../lib/scene_data.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/brdf.glsl"
#include "../lib/lights.glsl"
#include "../lib/normal_mapping.glsl"
#include "../lib/material.glsl"
#include "../lib/environment.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = TEXTURE_LINEAR_DEPTH) uniform sampler2DArray u_linear_depth;
layout(binding = TEXTURE_GBUFFER_ALBEDO) uniform sampler2DArray u_albedo;
layout(binding = TEXTURE_GBUFFER_NORMAL) uniform sampler2DArray u_normal;
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;
layout(std430, binding = BUFFER_PROBE_CENTRES) readonly buffer ProbeCentres { vec4 probe_centre[]; };  // world space
layout(location = 0) uniform int u_probe_size;  // face texels

// The direction through texel (x, y) of cube face f (GL's face order +X, -X, +Y, -Y, +Z, -Z
// and its (s, t) conventions, so that the sampler's cube lookup finds the same texel).
vec3 cube_direction(int face, vec2 st) {
    float s = st.x, t = st.y;
    if (face == 0) return vec3(1.0, -t, -s);
    if (face == 1) return vec3(-1.0, -t, s);
    if (face == 2) return vec3(s, 1.0, t);
    if (face == 3) return vec3(s, -1.0, -t);
    if (face == 4) return vec3(s, -t, 1.0);
    return vec3(-s, -t, -1.0);
}

#if STAGE == 0
#include "../lib/bvh.glsl"
#include "../lib/scene_geometry.glsl"
#include "../lib/scene_textures.glsl"
#include "../lib/ray_offset.glsl"
#include "../lib/trace_shade.glsl"
layout(binding = IMAGE_PROBES, rgba16f) writeonly uniform imageCubeArray o_probes;

void main() {
    lights_load();  // before any control flow (lib/lights.glsl)
    ivec3 id = ivec3(gl_GlobalInvocationID);
    if (id.x >= u_probe_size || id.y >= u_probe_size) return;
    vec2 st = (vec2(id.xy) + 0.5) / float(u_probe_size) * 2.0 - 1.0;
    vec3 dir = normalize(cube_direction(id.z % 6, st));
    ShadedHit s = trace_and_shade_w(probe_centre[id.z / 6].xyz, dir, true);
    imageStore(o_probes, id, vec4(s.radiance, s.hit ? s.t : -1.0));
}

#else
#include "../lib/cone_angle.glsl"
layout(binding = TEXTURE_PROBES) uniform samplerCubeArray u_probes;
layout(binding = TEXTURE_RAYS_SAMPLE) uniform sampler2DArray u_ray_sample;     // rays.sample
layout(binding = TEXTURE_RAYS_DIRECTION) uniform sampler2DArray u_ray_direction;  // rays.direction
layout(binding = IMAGE_RAYS_HIT, rgba32f) readonly uniform image2DArray io_ray_hit;  // rays.hit of the screen-space tracer
layout(binding = IMAGE_RAYS_RADIANCE, rgba32f) writeonly uniform image2DArray o_radiance;
layout(location = 1) uniform int u_probe_count;
layout(location = 2) uniform vec3 u_box_min;  // the proxy box: the scene bounds (world space)
layout(location = 3) uniform vec3 u_box_max;
// The refinement has settled when the probe's stored distance toward the estimated hit x
// matches |x - c|. Where they differ by more than PROBE_CONSISTENCY times the ray's length to
// x, the probe does not see the surface the ray meets (hidden from its centre, or no surface
// there: open scenes, whose bounds are no room) and the environment stands in. Measured
// (160x120, centre probe): without the check spheres_and_boxes' reflective error rose from
// 0.133 (environment) to 0.333; with 1.0 it is 0.132, while hall keeps its gain (0.041 ->
// 0.033); 0.3 also cost hall's 60-degree view half its gain.
const float PROBE_CONSISTENCY = 1.0;
#ifndef PARALLAX_STEPS
#define PARALLAX_STEPS 4  // distance refinements after the box projection (0: box projection only)
#endif

ivec2 origin_pixel(ivec2 q) {  // as lib/trace_common.glsl
    return min(q * ssr.downscale + ssr.downscale / 2, ivec2(frame.viewport.xy) - 1);
}

// As fallback_bvh (passes/trace_bvh.comp): a hit at full strength is resolved; a miss or a
// faded hit takes (fades toward) the probe.
bool screen_resolved(vec4 hit) {
    return hit.z > 0.5 && hit.w >= 1.0;
}

// Box projection (parallax-corrected cube maps): the ray from p along d leaves the proxy box
// at x = p + t d; the probe at c stores x in the direction x - c. Exact where the reflected
// surface is the box itself (a room's walls, floor, ceiling); nearer objects are displaced.
vec3 box_projected_point(vec3 p, vec3 d) {
    vec3 inv = 1.0 / d;  // +-inf on a zero component: that slab never limits t
    vec3 far_t = max((u_box_max - p) * inv, (u_box_min - p) * inv);
    float t = max(min(min(far_t.x, far_t.y), far_t.z), 0.0);
    return p + t * d;
}

void main() {
    lights_load();  // before any control flow (lib/lights.glsl)
    ivec3 id = ivec3(gl_GlobalInvocationID);  // (trace pixel, ray index)
    if (id.x >= ssr.trace_width || id.y >= ssr.trace_height) return;
    vec4 radiance = vec4(0.0, 0.0, 0.0, -2.0);
    vec4 smp = texelFetch(u_ray_sample, id, 0);
    if (!(smp.w > 0.5 && smp.x > 0.0)) {
        imageStore(o_radiance, id, radiance);
        return;
    }
    ivec2 p = origin_pixel(id.xy);
    GSample g = gbuffer_decode(texelFetch(u_albedo, ivec3(p, 0), 0), texelFetch(u_normal, ivec3(p, 0), 0),
                               texelFetch(u_material, ivec3(p, 0), 0));
    vec3 pos = view_position(vec2(p) + 0.5, texelFetch(u_linear_depth, ivec3(p, 0), 0).r);
    vec3 origin = pos + g.normal * (ssr.origin_bias * -pos.z);  // as lib/ray_generation.glsl
    vec3 dir = normalize(texelFetch(u_ray_direction, id, 0).xyz);
    vec4 hit = imageLoad(io_ray_hit, id);
    // No confidence test here (unlike fallback "bvh"): a probe sees the scene from its centre,
    // not from the ray's origin, so it cannot replace a screen-space hit the test doubts -- on
    // hall's mirror floor that made the floor 7 dB worse (README, "Hybrid reflections").
    if (!screen_resolved(hit)) {
        // The pre-filter (seed 004's roughness mips): a glossy ray looks up the mirror direction
        // at the level whose texel spans its GGX cone (lib/cone_angle.glsl, the cone holding half
        // the lobe), the split-sum's pre-filtered radiance; a mirror ray looks up its own
        // direction at level 0. Every ray of a pixel then brings the lobe's average.
        vec3 v = normalize(-pos);
        float n_dot_v = max(dot(g.normal, v), 1e-4);
        float alpha = g.roughness * g.roughness;
        bool mirror = alpha < 1e-4 || ssr.sampling == SAMPLING_MIRROR;
        vec3 look = mirror ? dir : reflect(-v, g.normal);
        float cone = mirror ? 0.0 : cone_angle(g.roughness, n_dot_v);
        vec3 p_w = (frame.inv_view * vec4(origin, 1.0)).xyz;
        vec3 d_w = normalize(mat3(frame.inv_view) * look);
        // The nearest probe to the ray's origin (seed 004: the local cube map of the area).
        int best = 0;
        float best_d = 1e30;
        for (int i = 0; i < u_probe_count; ++i) {
            float dd = distance(p_w, probe_centre[i].xyz);
            if (dd < best_d) {
                best_d = dd;
                best = i;
            }
        }
        vec3 c = probe_centre[best].xyz;
        vec3 p_box = clamp(p_w, u_box_min, u_box_max);
        vec3 x = box_projected_point(p_box, d_w);
        // The distance channel refines the box's guess (the distance impostors of
        // Szirmay-Kalos, Aszodi, Lazanyi and Premecz, 2005): the probe stores, in the direction
        // of the current guess x, the surface it saw at distance r; that surface point q,
        // projected back onto the ray, is the next guess. A few steps move x from the proxy box
        // onto the real walls (the bounds include the walls' thickness) and onto nearer objects.
        bool env = false;
        for (int k = 0; k < PARALLAX_STEPS; ++k) {
            vec3 l = x - c;
            float r = textureLod(u_probes, vec4(normalize(l), float(best)), 0.0).a;
            if (r < 0.0) {
                env = true;  // the probe saw the environment that way
                break;
            }
            vec3 q = c + normalize(l) * r;
            x = p_box + max(dot(q - p_box, d_w), 1e-4) * d_w;
        }
        vec3 l = x - c;
        float lx = max(length(l), 1e-6);
        float seen = textureLod(u_probes, vec4(l / lx, float(best)), 0.0).a;
        if (!env) env = seen < 0.0;
        if (!env && abs(seen - lx) > PROBE_CONSISTENCY * distance(x, p_w)) env = true;  // not settled
        // The cone's footprint at x (width 2 tan(cone) |x - p|) seen from the probe, in level-0
        // texels (a face spans 2 units of tangent over u_probe_size texels at distance 1).
        float footprint = 2.0 * tan(cone) * distance(x, p_w) / lx;
        float level = log2(max(footprint * float(u_probe_size) * 0.5, 1e-6));
        level = clamp(level, 0.0, float(textureQueryLevels(u_probes) - 1));
        // Where the probe saw the environment, the ray does too (seed 004's global cube map).
        if (env) radiance = vec4(environment_radiance(d_w), -1.0);
        else radiance = vec4(textureLod(u_probes, vec4(l / lx, float(best)), level).rgb, distance(x, p_w));
    }
    imageStore(o_radiance, id, radiance);
}
#endif
