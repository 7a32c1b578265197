#version 450 core
// reference: ground-truth reflections. Rays are traced against the scene's real triangles
// (lib/bvh.glsl) instead of the screen, and the surface each hits is shaded by the very
// material and lighting code the G-buffer uses (lib/material.glsl, lib/shading.glsl, the
// same shadow map), so SSR and reference differ only in what screen space cannot see or
// resolves wrongly. The reflected surface is seen from the camera by default, as the lit
// G-buffer has it; u_viewer = 1 views it from the ray's origin instead (the physical
// reflection, whose view-dependent specular differs). Two modes:
//   PER_RAY (0):   the rays an SSR frame traced (same directions; origins on the exact
//                  surface point, as below and as the BVH passes place them), one
//                  invocation per (trace pixel, ray): true hit, its position, its radiance.
//   CONVERGED (1): one invocation per pixel, rays_per_pixel rays drawn from the pixel's BRDF
//                  (one for a mirror), accumulated over dispatches of u_ray_count rays into
//                  (sum w c, sum w); the last dispatch writes the normalised reflection and
//                  the pixel's own direct light. The pixel's surface point is found exactly:
//                  the camera ray through the pixel centre is traced against the triangles,
//                  and reflection rays leave the hit point by the ulp offset of lib/ray_offset
//                  (Waechter and Binder 2019), not by SSR's origin_bias, so contact regions
//                  are neither darkened nor leaked through.
// Shadows: SHADOWS with the frame's shadow map (as the lit G-buffer has them), or
// TRACED_SHADOWS: a shadow ray from every shaded point toward each light that casts a shadow.
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

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = TEXTURE_LINEAR_DEPTH) uniform sampler2DArray u_linear_depth;
layout(binding = TEXTURE_GBUFFER_ALBEDO) uniform sampler2DArray u_albedo;
layout(binding = TEXTURE_GBUFFER_NORMAL) uniform sampler2DArray u_normal;
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;

#include "../lib/trace_shade.glsl"
#include "../lib/gbuffer_emission.glsl"
#include "../lib/gbuffer_specular.glsl"

uniform int u_first_ray;   // first ray index of this dispatch
uniform int u_ray_count;   // rays of this dispatch
uniform int u_last;        // 1: the last dispatch (converged: normalise)
uniform int u_viewer;      // 0: the camera views the reflected surface (as in the lit G-buffer); 1: the ray's origin

#if MODE == 0
layout(binding = TEXTURE_RAYS_DIRECTION) uniform sampler2DArray u_ray_direction;  // rays.direction of the SSR frame
layout(binding = TEXTURE_RAYS_SAMPLE) uniform sampler2DArray u_ray_sample;     // rays.sample
layout(binding = IMAGE_REFERENCE_HIT, rgba32f) writeonly uniform image2DArray o_hit;       // (x, y) pixels, object + 1, t
layout(binding = IMAGE_REFERENCE_POSITION, rgba32f) writeonly uniform image2DArray o_position;  // view-space hit, w: 1 if on screen
layout(binding = IMAGE_REFERENCE_RADIANCE, rgba32f) writeonly uniform image2DArray o_radiance;  // radiance, w: the ray's weight
#else
layout(binding = IMAGE_REFERENCE_ACCUM, rgba32f) uniform image2D o_accum;                    // (sum w c, sum w)
layout(binding = IMAGE_REFERENCE_REFLECTION, rgba32f) writeonly uniform image2D o_reflection;
layout(binding = IMAGE_REFERENCE_DIRECT, rgba32f) writeonly uniform image2DArray o_direct;    // the pixel's own direct light
#endif

GSample pixel_sample(ivec2 p) {
    return gbuffer_decode(texelFetch(u_albedo, ivec3(p, 0), 0), texelFetch(u_normal, ivec3(p, 0), 0),
                          texelFetch(u_material, ivec3(p, 0), 0));
}

void main() {
    lights_load();  // before any control flow (lib/lights.glsl)
#if MODE == 0
    ivec3 id = ivec3(gl_GlobalInvocationID.xy, int(gl_GlobalInvocationID.z) + u_first_ray);
    if (id.x >= ssr.trace_width || id.y >= ssr.trace_height || id.z >= u_first_ray + u_ray_count) return;
    vec4 smp = texelFetch(u_ray_sample, id, 0);
    vec4 hit = vec4(0.0), position = vec4(0.0), radiance = vec4(0.0, 0.0, 0.0, smp.x);
    if (smp.w > 0.5 && smp.x > 0.0) {
        // The SSR ray's direction, from the surface point itself (as the converged mode and the
        // BVH passes place origins: lib/trace_shade.glsl's surface_origin_w), not from SSR's
        // origin_bias, whose lift is part of SSR's error.
        ivec2 p = min(id.xy * ssr.downscale + ssr.downscale / 2, ivec2(frame.viewport.xy) - 1);
        GSample g = pixel_sample(p);
        vec3 pos = view_position(vec2(p) + 0.5, texelFetch(u_linear_depth, ivec3(p, 0), 0).r);
        vec3 dir = normalize(texelFetch(u_ray_direction, id, 0).xyz);
        ShadedHit s = trace_and_shade_w(surface_origin_w(p, g, pos), normalize(mat3(frame.inv_view) * dir),
                                        u_viewer != 0);
        radiance.rgb = s.radiance;
        if (s.hit) {
            vec4 c = frame.proj * vec4(s.position, 1.0);
            vec2 px = (c.xy / c.w * 0.5 + 0.5) * frame.viewport.xy;
            bool on_screen = c.w > frame.clip.x && all(greaterThanEqual(px, vec2(0.0))) &&
                             all(lessThan(px, frame.viewport.xy));
            hit = vec4(px, float(s.object + 1), s.t);
            position = vec4(s.position, on_screen ? 1.0 : 0.0);
        }
    }
    imageStore(o_hit, id, hit);
    imageStore(o_position, id, position);
    imageStore(o_radiance, id, radiance);
#else
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, ivec2(frame.viewport.xy)))) return;
#if defined(EXTERNAL_TRACE) && EXTERNAL_TRACE
    trace_invocation = p.y * int(frame.viewport.x) + p.x;
#endif
    GSample g = pixel_sample(p);
    bool mirror = g.roughness * g.roughness < 1e-4 || ssr.sampling == SAMPLING_MIRROR;
    // Cost that follows the work: after the first dispatch a pixel that does not reflect, or a
    // mirror whose one ray is traced, has nothing to add until the last dispatch normalises.
    if (u_first_ray > 0 && u_last == 0 && (!is_reflective(g) || mirror)) {
        trace_finish();
        return;
    }
    vec4 acc = u_first_ray == 0 ? vec4(0.0) : imageLoad(o_accum, p);
    vec3 pos = view_position(vec2(p) + 0.5, texelFetch(u_linear_depth, ivec3(p, 0), 0).r);
    // The pixel's surface point, exactly: the camera ray through the pixel centre. Where it
    // finds another object than the G-buffer's (a silhouette the two sample differently), the
    // G-buffer point and SSR's origin offset stand in.
    vec3 camera_w = frame.inv_view[3].xyz;
    vec3 pixel_dir_w = normalize(mat3(frame.inv_view) * normalize(view_position(vec2(p) + 0.5, 1.0)));
    trace_chain_begin(0);  // (lib/trace_external.glsl: chain 0 the camera ray, 1.. each reflection ray, then the pixel's own light)
    TraceHit primary = trace_closest(camera_w, pixel_dir_w, 0.0, 3.4e38);
    bool exact = g.covered && primary.triangle >= 0 && floatBitsToInt(bvh_triangles[primary.triangle].v0.w) == g.object_id;
    vec3 origin_w = vec3(0.0);
    if (exact) {
        vec3 point_w = hit_point_w(primary);
        vec3 normal_w = hit_normal_w(primary, -pixel_dir_w);
        pos = (frame.view * vec4(point_w, 1.0)).xyz;
        origin_w = offset_ray_origin(point_w, normal_w);
    }
    // The truth reflects wherever a surface does, whatever SSR's roughness cutoff (the
    // uploaded settings set it to 1).
    if (is_reflective(g)) {
        for (int r = u_first_ray; r < u_first_ray + u_ray_count; ++r) {
            if (mirror && r > 0) break;  // one ray serves a mirror
            trace_chain_begin(1 + r - u_first_ray);
            ReflectionRay ray = generate_ray(g, pos, p, r);
            if (ray.weight <= 0.0) continue;
            ShadedHit s = exact ? trace_and_shade_w(origin_w, normalize(mat3(frame.inv_view) * ray.dir), u_viewer != 0)
                                : trace_and_shade(ray.origin, ray.dir, u_viewer != 0);
            acc += vec4(ray.weight * s.radiance, ray.weight);
        }
    }
    vec3 reflection = vec3(0.0), direct = vec3(0.0);
    if (u_last != 0) {
        vec3 v = normalize(-pos);
        if (is_reflective(g))
            reflection = acc.w > 0.0 ? acc.rgb / acc.w
                                     : environment_radiance(normalize(mat3(frame.inv_view) * reflect(-v, g.normal)));
        // The pixel's own direct light, shaded at its exact point (as the lighting pass shades
        // the G-buffer's), so that the reference's final image has exact shadows too.
        trace_chain_begin(1 + u_ray_count);
        if (g.covered) {
            if (exact) {
                surface_point_w = hit_point_w(primary);
                surface_normal_w = hit_normal_w(primary, -pixel_dir_w);
            } else {
                surface_point_w = (frame.inv_view * vec4(pos + g.normal * (ssr.origin_bias * -pos.z), 1.0)).xyz;
                surface_normal_w = normalize(mat3(frame.inv_view) * g.normal);
            }
            direct = shade_surface(g, gbuffer_emission(ivec3(p, 0), g), gbuffer_dielectric_f0(ivec3(p, 0), g), pos, normalize(-pos));
        }
    }
    // (With rays traced outside the shader, only the run whose every ray was answered writes.)
    if (trace_complete()) {
        imageStore(o_accum, p, acc);
        if (u_last != 0) {
            imageStore(o_reflection, p, vec4(reflection, 1.0));
            imageStore(o_direct, ivec3(p, 0), vec4(direct, 1.0));
        }
    }
    trace_finish();
#endif
}
