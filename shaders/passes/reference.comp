#version 450 core
// reference: ground-truth reflections. Rays are traced against the scene's real triangles
// (lib/bvh.glsl) instead of the screen, and the surface each hits is shaded by the very
// material and lighting code the G-buffer uses (lib/material.glsl, lib/shading.glsl, the
// same shadow map), so SSR and reference differ only in what screen space cannot see or
// resolves wrongly. The reflected surface is seen from the camera by default, as the lit
// G-buffer has it; u_viewer = 1 views it from the ray's origin instead (the physical
// reflection, whose view-dependent specular differs). Two modes:
//   PER_RAY (0):   the rays an SSR frame traced (same origins and directions), one
//                  invocation per (trace pixel, ray): true hit, its position, its radiance.
//   CONVERGED (1): one invocation per pixel, rays_per_pixel rays drawn from the pixel's BRDF
//                  (one for a mirror), accumulated over dispatches of u_ray_count rays into
//                  (sum w c, sum w); the last dispatch writes the normalised reflection.
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

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler2DArray u_linear_depth;
layout(binding = 1) uniform sampler2DArray u_albedo;
layout(binding = 2) uniform sampler2DArray u_normal;
layout(binding = 3) uniform sampler2DArray u_material;
layout(binding = 4) uniform sampler2DShadow u_shadow_map;
#include "../lib/shadow_map.glsl"
#include "../lib/shading.glsl"

uniform int u_first_ray;   // first ray index of this dispatch
uniform int u_ray_count;   // rays of this dispatch
uniform int u_last;        // 1: the last dispatch (converged: normalise)
uniform int u_viewer;      // 0: the camera views the reflected surface (as in the lit G-buffer); 1: the ray's origin

#if MODE == 0
layout(binding = 5) uniform sampler2DArray u_ray_direction;  // rays.direction of the SSR frame
layout(binding = 6) uniform sampler2DArray u_ray_sample;     // rays.sample
layout(binding = 0, rgba32f) writeonly uniform image2DArray o_hit;       // (x, y) pixels, object + 1, t
layout(binding = 1, rgba32f) writeonly uniform image2DArray o_position;  // view-space hit, w: 1 if on screen
layout(binding = 2, rgba32f) writeonly uniform image2DArray o_radiance;  // radiance, w: the ray's weight
#else
layout(binding = 0, rgba32f) uniform image2D o_accum;                    // (sum w c, sum w)
layout(binding = 1, rgba32f) writeonly uniform image2D o_reflection;
#endif

GSample pixel_sample(ivec2 p) {
    return gbuffer_decode(texelFetch(u_albedo, ivec3(p, 0), 0), texelFetch(u_normal, ivec3(p, 0), 0),
                          texelFetch(u_material, ivec3(p, 0), 0));
}

struct ShadedHit {
    bool hit;
    int object;
    float t;
    vec3 position;  // view space
    vec3 radiance;
};

// Traces a view-space ray through the scene and shades what it hits (or the environment).
ShadedHit trace_and_shade(vec3 origin, vec3 dir) {
    ShadedHit s;
    vec3 origin_w = (frame.inv_view * vec4(origin, 1.0)).xyz;
    vec3 dir_w = normalize(mat3(frame.inv_view) * dir);
    TraceHit h = trace_closest(origin_w, dir_w, 0.0, ssr.max_distance);
    s.hit = h.triangle >= 0;
    s.object = -1;
    s.t = h.t;
    s.position = origin + dir * h.t;
    if (!s.hit) {
        s.radiance = environment_radiance(dir_w);
        return s;
    }
    BvhTriangle tri = bvh_triangles[h.triangle];
    s.object = floatBitsToInt(tri.v0.w);
    ObjectData o = objects[s.object];
    MaterialData m = materials[o.material.x];
    SurfaceAttributes a = triangle_attributes(o, floatBitsToInt(tri.v1.w), h.b1, h.b2);
    mat3 model_view = mat3(frame.view) * mat3(o.model);
    vec3 n = normalize(mat3(frame.view) * (mat3(o.normal_matrix) * a.normal));
    vec3 face = cross(model_view * (a.p1 - a.p0), model_view * (a.p2 - a.p0));  // counter-clockwise = front
    bool front_facing = dot(face, -s.position) > 0.0;  // as the camera would see it
    vec3 t, b;
    bool has_frame = false;
    if (m.flags.z != 0) {
        has_frame = tangent_frame_from_vertex(n, vec4(model_view * a.tangent.xyz, a.tangent.w), t, b) ||
                    tangent_frame_from_gradients(n, model_view * (a.p1 - a.p0), model_view * (a.p2 - a.p0),
                                                 a.uv1 - a.uv0, a.uv2 - a.uv0, t, b);
    }
    GSample g = material_sample(m, sample_image(m.images.x, a.uv, m.wraps.x, true),
                                sample_image(m.images.y, a.uv, m.wraps.y, false),
                                sample_image(m.images.z, a.uv, m.wraps.z, false).xyz, n, t, b, has_frame,
                                front_facing, s.object);
    vec3 viewer = u_viewer == 0 ? normalize(-s.position) : -dir;
    s.radiance = shade_surface(g, s.position, viewer);
    return s;
}

void main() {
#if MODE == 0
    ivec3 id = ivec3(gl_GlobalInvocationID.xy, int(gl_GlobalInvocationID.z) + u_first_ray);
    if (id.x >= ssr.trace_width || id.y >= ssr.trace_height || id.z >= u_first_ray + u_ray_count) return;
    vec4 smp = texelFetch(u_ray_sample, id, 0);
    vec4 hit = vec4(0.0), position = vec4(0.0), radiance = vec4(0.0, 0.0, 0.0, smp.x);
    if (smp.w > 0.5 && smp.x > 0.0) {
        // The SSR ray's own origin (as ray_generation.glsl placed it) and direction.
        ivec2 p = min(id.xy * ssr.downscale + ssr.downscale / 2, ivec2(frame.viewport.xy) - 1);
        GSample g = pixel_sample(p);
        vec3 pos = view_position(vec2(p) + 0.5, texelFetch(u_linear_depth, ivec3(p, 0), 0).r);
        vec3 origin = pos + g.normal * (ssr.origin_bias * -pos.z);
        vec3 dir = normalize(texelFetch(u_ray_direction, id, 0).xyz);
        ShadedHit s = trace_and_shade(origin, dir);
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
    vec4 acc = u_first_ray == 0 ? vec4(0.0) : imageLoad(o_accum, p);
    GSample g = pixel_sample(p);
    vec3 pos = view_position(vec2(p) + 0.5, texelFetch(u_linear_depth, ivec3(p, 0), 0).r);
    // The truth reflects wherever a surface does, whatever SSR's roughness cutoff (the
    // uploaded settings set it to 1).
    if (is_reflective(g)) {
        bool mirror = g.roughness * g.roughness < 1e-4 || ssr.sampling == SAMPLING_MIRROR;
        for (int r = u_first_ray; r < u_first_ray + u_ray_count; ++r) {
            if (mirror && r > 0) break;  // one ray serves a mirror
            ReflectionRay ray = generate_ray(g, pos, p, r);
            if (ray.weight <= 0.0) continue;
            acc += vec4(ray.weight * trace_and_shade(ray.origin, ray.dir).radiance, ray.weight);
        }
    }
    imageStore(o_accum, p, acc);
    if (u_last != 0) {
        vec3 v = normalize(-pos);
        vec3 reflection = vec3(0.0);
        if (is_reflective(g))
            reflection = acc.w > 0.0 ? acc.rgb / acc.w
                                     : environment_radiance(normalize(mat3(frame.inv_view) * reflect(-v, g.normal)));
        imageStore(o_reflection, p, vec4(reflection, 1.0));
    }
#endif
}
