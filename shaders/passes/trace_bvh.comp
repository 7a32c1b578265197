#version 450 core
// trace_bvh: reflection rays traced against the scene's triangles, with the
// trace-and-shade code of the reference pass (lib/trace_shade.glsl): the BVH hit shaded by the
// G-buffer's own material and lighting code and the frame's shadow map (SHADOWS) or a traced
// shadow ray (TRACED_SHADOWS, Settings.bvh_shadows "traced"), seen from the ray's origin: the
// physical reflection, as the converged reference's default viewer "ray" sees it. One invocation per (trace pixel, ray). Two modes:
//   FALLBACK 0 (method "bvh", seed 003's ray-traced reflections): every ray of the frame,
//              generated exactly as the screen-space tracers generate it
//              (lib/ray_generation.glsl), no screen space at all. Writes the rays.* outputs
//              of the screen-space tracers (rays.hit always a screen miss: the radiance comes
//              from rays.radiance) and rays.radiance. With COMPACT (Settings.skip)
//              in the same three stages as the fallback: 0 draws every ray (one invocation
//              per trace pixel) and lists those with a weight, 2 traces the list, so that an
//              adaptive pixel's
//              unused ray slots (adaptive_rays) and matte pixels leave no idle SIMD lanes
//              beside a neighbour's BVH traversal.
//   FALLBACK 1 (fallback "bvh"; thesis 4.3's hybrid, seed 004's fallback hierarchy): after a
//              screen-space tracer, the rays it could not resolve (a miss: it left the screen,
//              reached its step limit or ran behind every layer; or a faded hit) are retraced
//              from their origin; the others are skipped. Three stages (STAGE): 0 selects,
//              full-screen, the rays to retrace and appends them to a compacted list (an
//              atomic counter); 1 turns the count into the indirect dispatch's group count;
//              2 traces the listed rays only, so the BVH's cost follows the misses.
//              With CONFIDENCE, a screen-space hit must also pass a confidence test
//              (lib/screen_confidence.glsl) or it is retraced too; its rays.hit becomes a miss
//              marked (0, 0, 0, -1), as the tracer marks a ray it handed over where the ray
//              left the G-buffer's sight (STOP_UNSEEN, lib/screen_sight.glsl), so the resolve
//              takes the BVH's radiance; a kept hit moves to the pixel the ray crosses.
// rays.radiance (RGBA32F): rgb the BVH radiance (the environment's where the BVH found
// nothing), a the hit's distance along the ray (world units); a = -1: the BVH found nothing,
// a = -2: not traced by the BVH (no ray, or method "bvh"'s slot without one). With FALLBACK, a
// screen-space hit kept at full strength holds the hit's surface shaded from the ray's origin
// (shade_screen_hit) and its distance: the resolve uses it instead of the lit G-buffer's.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/ssr_settings.glsl"
#include "../lib/scene_data.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/brdf.glsl"
#include "../lib/lights.glsl"
#include "../lib/random.glsl"
#include "../lib/ggx_sampling.glsl"
#include "../lib/ray_generation.glsl"
#include "../lib/normal_mapping.glsl"
#include "../lib/material.glsl"
#include "../lib/environment.glsl"
#include "../lib/bvh.glsl"
#include "../lib/scene_geometry.glsl"
#include "../lib/scene_textures.glsl"
#include "../lib/ray_offset.glsl"

#ifndef COMPACT
#define COMPACT 0
#endif
// The passes that run over a compacted list of rays: the fallback, and method "bvh" with skip.
#define LISTED (FALLBACK || COMPACT)

#if LISTED && STAGE == 2
layout(local_size_x = 64, local_size_y = 1, local_size_z = 1) in;
#elif LISTED && STAGE == 1
layout(local_size_x = 1, local_size_y = 1, local_size_z = 1) in;
#else
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
#endif

layout(binding = TEXTURE_LINEAR_DEPTH) uniform sampler2DArray u_linear_depth;
layout(binding = TEXTURE_GBUFFER_ALBEDO) uniform sampler2DArray u_albedo;
layout(binding = TEXTURE_GBUFFER_NORMAL) uniform sampler2DArray u_normal;
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;
#include "../lib/trace_shade.glsl"

#if FALLBACK
layout(binding = IMAGE_RAYS_HIT, rgba32f) uniform image2DArray io_ray_hit;  // rays.hit of the screen-space tracer
layout(binding = TEXTURE_RAYS_SAMPLE) uniform sampler2DArray u_ray_sample;     // rays.sample
layout(binding = TEXTURE_RAYS_DIRECTION) uniform sampler2DArray u_ray_direction;  // rays.direction
layout(binding = IMAGE_RAYS_RADIANCE, rgba32f) writeonly uniform image2DArray o_radiance;

ivec2 origin_pixel(ivec2 q) {  // as lib/trace_common.glsl
    return min(q * ssr.downscale + ssr.downscale / 2, ivec2(frame.viewport.xy) - 1);
}
#else
// The outputs of lib/trace_common.glsl, but with rays.direction readable: the direction is
// read back as stored (RGBA32F), so that the per-ray reference, which reads rays.direction,
// traces exactly the ray this pass traces (same invocation: the load sees the store).
layout(binding = IMAGE_RAYS_HIT, rgba32f) writeonly uniform image2DArray o_hit;
layout(binding = IMAGE_RAYS_SAMPLE, rgba32f) writeonly uniform image2DArray o_sample;
layout(binding = IMAGE_RAYS_DIRECTION, rgba32f) uniform image2DArray o_direction;
layout(binding = IMAGE_RAYS_RADIANCE, rgba32f) writeonly uniform image2DArray o_radiance;

ivec2 origin_pixel(ivec2 q) {  // as lib/trace_common.glsl
    return min(q * ssr.downscale + ssr.downscale / 2, ivec2(frame.viewport.xy) - 1);
}
#endif

#if LISTED
// The compacted list: the (trace pixel, ray) of every ray to (re)trace, and the count and the
// indirect dispatch's group counts (x, y, z).
layout(std430, binding = BUFFER_RETRACE_LIST) buffer RetraceList { ivec4 retrace[]; };
layout(std430, binding = BUFFER_RETRACE_COUNT) buffer RetraceCount { uint retrace_count; uint groups[3]; };
#endif

#if FALLBACK
#include "../lib/screen_confidence.glsl"
#include "../lib/gbuffer_emission.glsl"
#include "../lib/gbuffer_specular.glsl"
#endif

#if FALLBACK
// The radiance a screen-space hit (hit.xy pixel, hit.z 1-based layer) sends back along `dir`:
// the G-buffer's surface at the hit, shaded by lib/shading.glsl with the ray's origin as the
// viewer, where the ray crosses the face the pixel lies on (lib/screen_confidence.glsl), not at
// the pixel's centre, with the shading normal interpolated there: a shadow edge, a highlight or
// the light's terminator inside one pixel of a small image is resolved as the ray meets it
// (a curved surface's pixel-centre normal left rings of 0.02-0.05 around reflected spheres).
// Shadows as the BVH's hits get them: the shadow map, or a ray from the surface.
vec4 shade_screen_hit(vec4 hit, vec3 origin, vec3 dir) {
    ivec3 hp = ivec3(clamp(ivec2(hit.xy), ivec2(0), ivec2(frame.viewport.xy) - 1), int(hit.z) - 1);
    ScreenSurface s = screen_surface(hp.xy, hp.z);
    vec3 p = s.point, x;
    if (face_crossing(s, origin, dir, x) && distance(x, p) < 2.0 * pixel_footprint(-p.z)) p = x;
    s.g.normal = screen_normal_at(hp.xy, hp.z, view_to_window(p), s.g);
    // A traced shadow leaves from the point itself, as the BVH's hits leave their triangle, not
    // lifted by origin_bias (2 cm at 10 m, which moved shadow edges by as much, magnified by a
    // mirror floor: hall's pews and columns lit in patches where the reference's shadow ray is
    // blocked). A point rebuilt from the G-buffer lies on the face's estimated plane, not on the
    // triangle itself, so the shadow ray ignores its own object within one pixel footprint: its
    // surface there is what the G-buffer cannot resolve (lib/bvh.glsl's bvh_skip_object).
    surface_normal_w = normalize(mat3(frame.inv_view) * s.face);
    surface_point_w = (frame.inv_view * vec4(p, 1.0)).xyz;
    bvh_skip_object = s.g.object_id;
    bvh_skip_t = pixel_footprint(-p.z);
    vec3 c = shade_surface(s.g, gbuffer_emission(hp, s.g), gbuffer_dielectric_f0(hp, s.g), p, -dir);
    bvh_skip_object = -1;
    return vec4(c, distance(origin, p));
}
#endif

// Whether screen space resolved a ray fully: a hit at full strength. A miss or a faded hit
// (screen border, toward the camera, distance) is what the BVH continues.
bool screen_resolved(vec4 hit) {
    return hit.z > 0.5 && hit.w >= 1.0;
}

void main() {
    lights_load();  // before any control flow (lib/lights.glsl)
#if LISTED && STAGE == 1
    groups[0] = (retrace_count + 63u) / 64u;
    groups[1] = 1u;
    groups[2] = 1u;
    return;
#endif
#if LISTED && STAGE == 2
    if (gl_GlobalInvocationID.x >= retrace_count) return;
    ivec3 id = retrace[gl_GlobalInvocationID.x].xyz;
#else
    ivec3 id = ivec3(gl_GlobalInvocationID);  // (trace pixel, ray index)
#endif
    if (id.x >= ssr.trace_width || id.y >= ssr.trace_height) return;
    ivec2 p = origin_pixel(id.xy);
    GSample g = gbuffer_decode(texelFetch(u_albedo, ivec3(p, 0), 0), texelFetch(u_normal, ivec3(p, 0), 0),
                               texelFetch(u_material, ivec3(p, 0), 0));
    vec3 pos = view_position(vec2(p) + 0.5, texelFetch(u_linear_depth, ivec3(p, 0), 0).r);
    vec4 radiance = vec4(0.0, 0.0, 0.0, -2.0);
#if FALLBACK && STAGE == 2
    // Retraced from the surface point itself (lib/trace_shade.glsl: surface_origin_w), as the
    // per-ray and converged references place their origins, not from SSR's biased one.
    vec3 dir = normalize(texelFetch(u_ray_direction, id, 0).xyz);
    ShadedHit s = trace_and_shade_w(surface_origin_w(p, g, pos), normalize(mat3(frame.inv_view) * dir), true);
    radiance = vec4(s.radiance, s.hit ? s.t : -1.0);
#elif COMPACT && STAGE == 2
    // The ray stage 0 drew and stored, traced as the full-screen dispatch traces it.
    vec3 dir = normalize(imageLoad(o_direction, id).xyz);
    ShadedHit s = trace_and_shade_w(surface_origin_w(p, g, pos), normalize(mat3(frame.inv_view) * dir), true);
    radiance = vec4(s.radiance, s.hit ? s.t : -1.0);
#elif FALLBACK
    vec4 smp = texelFetch(u_ray_sample, id, 0);
    vec4 hit = imageLoad(io_ray_hit, id);
    // The ray from the surface point itself, as the BVH retraces it and the references trace it,
    // not from SSR's origin lifted by origin_bias: the lift moves where the ray meets the
    // surface it hits by origin_bias x depth (2 cm at 10 m for 0.002), and a mirror floor
    // magnifies that across many pixels wherever the hit surface's shading changes (a shadow's
    // edge on hall's columns: 0.45 off over a patch of the floor).
    vec3 origin = pos;
    vec3 dir = normalize(texelFetch(u_ray_direction, id, 0).xyz);
    bool resolved = screen_resolved(hit);
#if CONFIDENCE
    if (smp.w > 0.5 && smp.x > 0.0 && resolved) {
        resolved = screen_hit_confident(hit, origin, dir);
        // Rejected: a miss marked (0, 0, 0, -1), the BVH's radiance replaces it; kept: the
        // pixel the ray settles on, which the resolve measures the hit's distance to.
        imageStore(io_ray_hit, id, resolved ? hit : vec4(0.0, 0.0, 0.0, -1.0));
    }
#endif
    if (smp.w > 0.5 && smp.x > 0.0 && !resolved) retrace[atomicAdd(retrace_count, 1u)] = ivec4(id, 0);
    // A kept screen-space hit is shaded here as the BVH shades its own hits: viewed from the
    // ray's origin. The lit G-buffer holds the surface as the camera sees it, which differs from
    // what the ray sees wherever the surface's specular lobe is lit (a highlight in a mirror:
    // 0.5 in the lit G-buffer against 1.7 along the ray on hall's floor seen at 60 degrees).
    if (smp.w > 0.5 && smp.x > 0.0 && resolved) radiance = shade_screen_hit(hit, origin, dir);
#elif COMPACT
    // Stage 0 of method "bvh" with the list: one invocation per trace pixel (id.z = 0) draws
    // all its ray slots from one G-buffer decode, writes what the full-screen dispatch writes
    // (radiance: not traced yet), and lists the rays with a weight with one atomic.
    uint drawn = 0u;  // rays_per_pixel <= 32 (Settings)
    for (int r = 0; r < ssr.rays_per_pixel; ++r) {
        ivec3 rid = ivec3(id.xy, r);
        ReflectionRay ray = generate_ray(g, pos, id.xy, r);
        bool traces = is_reflective(g) && ray.dir != vec3(0.0);  // else zeros, as lib/trace_common.glsl
        imageStore(o_hit, rid, vec4(0.0));
        imageStore(o_sample, rid, traces ? vec4(ray.weight, ray.pdf, 0.0, 1.0) : vec4(0.0));
        imageStore(o_direction, rid, traces ? vec4(ray.dir, 0.0) : vec4(0.0));
        imageStore(o_radiance, rid, radiance);
        if (ray.weight > 0.0) drawn |= 1u << uint(r);
    }
    if (drawn == 0u) return;
    uint at = atomicAdd(retrace_count, uint(bitCount(drawn)));
    for (int r = 0; r < ssr.rays_per_pixel; ++r)
        if ((drawn & (1u << uint(r))) != 0u) retrace[at++] = ivec4(id.xy, r, 0);
    return;
#else
    ReflectionRay ray = generate_ray(g, pos, id.xy, id.z);
    // rays.hit: never a screen-space hit (the radiance is in rays.radiance); rays.sample: no
    // depth fetches.
    // A surface that traces no ray at all (direction 0) gets zeros, as lib/trace_common.glsl.
    bool traces = is_reflective(g) && ray.dir != vec3(0.0);
    imageStore(o_hit, id, vec4(0.0));
    imageStore(o_sample, id, traces ? vec4(ray.weight, ray.pdf, 0.0, 1.0) : vec4(0.0));
    imageStore(o_direction, id, traces ? vec4(ray.dir, 0.0) : vec4(0.0));
    if (ray.weight > 0.0) {
        vec3 dir = normalize(imageLoad(o_direction, id).xyz);
        // From the surface point itself, not ray.origin (SSR's origin_bias): see surface_origin_w.
        ShadedHit s = trace_and_shade_w(surface_origin_w(p, g, pos), normalize(mat3(frame.inv_view) * dir), true);
        radiance = vec4(s.radiance, s.hit ? s.t : -1.0);
    }
#endif
    imageStore(o_radiance, id, radiance);
}
