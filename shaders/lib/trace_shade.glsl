// Trace and shade: a world-space ray traced against the scene's triangles
// (lib/bvh.glsl) and the surface it hits shaded by the very material and lighting code the
// G-buffer uses (lib/material.glsl, lib/shading.glsl), so that what the BVH finds matches
// what the lit G-buffer would show. Shared by the reference pass and the ray-traced
// reflection passes (trace_bvh: method "bvh" and fallback "bvh"), which therefore produce
// the same radiance for the same ray.
// Needs frame_uniforms, depth_convention, ssr_settings, scene_data, gbuffer, brdf, lights,
// normal_mapping, material, environment, bvh, scene_geometry, scene_textures, ray_offset.
// The including shader defines SHADOWS and TRACED_SHADOWS (0 or 1), with SHADOWS also
// SHADOW_MAPS and SHADOW_CUBES (lib/shadow_map.glsl declares the maps it reads).

// The surface point being shaded, in world space, with its geometric normal on the side its
// viewer is: what a traced shadow ray leaves from (light_visibility has no room for it).
vec3 surface_point_w;
vec3 surface_normal_w;

#if TRACED_SHADOWS
// The lights that cast shadows (those the shadow maps hold), with a ray instead of a map.
float light_visibility(LightData light, vec3 p_view, vec3 n_view, vec3 l_view, float light_distance) {
    if (light.direction_shadow.w <= 0.5) return 1.0;
    vec3 l_w = normalize(mat3(frame.inv_view) * l_view);
    if (dot(surface_normal_w, l_w) <= 0.0) return 0.0;  // the surface itself is in the way
    return trace_occluded(offset_ray_origin(surface_point_w, surface_normal_w), l_w, 0.0, light_distance) ? 0.0 : 1.0;
}
#else
#include "../lib/shadow_map.glsl"
#endif
#include "../lib/shading.glsl"

struct ShadedHit {
    bool hit;
    int object;
    float t;
    vec3 position;  // view space
    vec3 radiance;
};

// A hit's world-space point, interpolated from its triangle's vertices (so that it lies on
// the triangle to a few ulps, as lib/ray_offset.glsl assumes), and the triangle's unit
// geometric normal on the side `toward` points to.
vec3 hit_point_w(TraceHit h) {
    BvhTriangle tri = bvh_triangles[h.triangle];
    return tri.v0.xyz * (1.0 - h.b1 - h.b2) + tri.v1.xyz * h.b1 + tri.v2.xyz * h.b2;
}
vec3 hit_normal_w(TraceHit h, vec3 toward) {
    BvhTriangle tri = bvh_triangles[h.triangle];
    vec3 n = normalize(cross(tri.v1.xyz - tri.v0.xyz, tri.v2.xyz - tri.v0.xyz));
    return dot(n, toward) >= 0.0 ? n : -n;
}

// The world-space origin of a reflection ray leaving pixel p's G-buffer surface (view-space
// point pos, reconstructed from the linear depth), placed as the converged reference places
// its own: the camera ray through the pixel centre traced against the triangles and, where it
// meets the G-buffer's object, its hit point moved off the triangle by lib/ray_offset's ulp
// offset along the geometric normal (Waechter and Binder 2019). Elsewhere (a silhouette the
// rasteriser and the trace sample differently) SSR's origin: pos + origin_bias along the normal.
// Why: origin_bias lifts the origin by a fraction of its depth (2.5 mm at 5 m for
// 0.0005), which shifts every edge a reflection ray meets by a fraction of a pixel; on a mirror
// floor a whole row of pixels along each such edge then sees past it (hall's 60-degree view:
// 36.0 dB against the converged reference at 640x360, 45 dB with this origin).
vec3 surface_origin_w(ivec2 p, GSample g, vec3 pos) {
    vec3 camera_w = frame.inv_view[3].xyz;
    vec3 pixel_dir_w = normalize(mat3(frame.inv_view) * normalize(view_position(vec2(p) + 0.5, 1.0)));
    TraceHit primary = trace_closest(camera_w, pixel_dir_w, 0.0, 3.4e38);
    if (g.covered && primary.triangle >= 0 && floatBitsToInt(bvh_triangles[primary.triangle].v0.w) == g.object_id)
        return offset_ray_origin(hit_point_w(primary), hit_normal_w(primary, -pixel_dir_w));
    return (frame.inv_view * vec4(pos + g.normal * (ssr.origin_bias * -pos.z), 1.0)).xyz;
}

// Traces a world-space ray through the scene and shades what it hits (or the environment).
// viewer_is_ray: the hit is viewed from the ray's origin (the physical reflection) instead
// of from the camera (as the lit G-buffer has it).
ShadedHit trace_and_shade_w(vec3 origin_w, vec3 dir_w, bool viewer_is_ray) {
    ShadedHit s;
    TraceHit h = trace_closest(origin_w, dir_w, 0.0, ssr.max_distance);
    s.hit = h.triangle >= 0;
    s.object = -1;
    s.t = h.t;
    s.position = (frame.view * vec4(origin_w + dir_w * h.t, 1.0)).xyz;
    if (!s.hit) {
        s.radiance = environment_radiance(dir_w);
        return s;
    }
    surface_point_w = hit_point_w(h);
    surface_normal_w = hit_normal_w(h, -dir_w);
    s.position = (frame.view * vec4(surface_point_w, 1.0)).xyz;
    BvhTriangle tri = bvh_triangles[h.triangle];
    s.object = floatBitsToInt(tri.v0.w);
    ObjectData o = objects[s.object];
    MaterialData m = materials[o.material.x];
    SurfaceAttributes a = triangle_attributes(o, floatBitsToInt(tri.v1.w), h.b1, h.b2);
    mat3 model_view = mat3(frame.view) * mat3(o.model);
    vec3 n = normalize(mat3(frame.view) * (mat3(o.normal_matrix) * a.normal));
    vec3 face = cross(model_view * (a.p1 - a.p0), model_view * (a.p2 - a.p0));  // counter-clockwise = front
#if defined(FACING_FROM_RAY) && FACING_FROM_RAY
    // (the probes' capture: the side the probe's ray meets, for double-sided materials)
    bool front_facing = dot(face, -(mat3(frame.view) * dir_w)) > 0.0;
#else
    bool front_facing = dot(face, -s.position) > 0.0;  // as the camera would see it
#endif
    vec3 t, b;
    bool has_frame = false;
    if (m.flags.z != 0) {
        has_frame = tangent_frame_from_vertex(n, vec4(model_view * a.tangent.xyz, a.tangent.w), texture_linear(m, 2), t, b) ||
                    tangent_frame_from_gradients(n, model_view * (a.p1 - a.p0), model_view * (a.p2 - a.p0),
                                                 texture_uv(m, 2, a.uv1) - texture_uv(m, 2, a.uv0),
                                                 texture_uv(m, 2, a.uv2) - texture_uv(m, 2, a.uv0), t, b);
    }
    // Each texture at its own coordinates (KHR_texture_transform), as the G-buffer samples them.
    GSample g = material_sample(m, sample_image(m.images.x, texture_uv(m, 0, a.uv), m.wraps.x, true),
                                sample_image(m.images.y, texture_uv(m, 1, a.uv), m.wraps.y, false),
                                sample_image(m.images.z, texture_uv(m, 2, a.uv), m.wraps.z, false).xyz, n, t, b, has_frame,
                                front_facing, s.object);
    g.albedo *= a.color.rgb;  // glTF COLOR_0, as the G-buffer's shading multiplies it
    vec3 emission = material_emission(m, sample_image(m.images.w, texture_uv(m, 3, a.uv), m.wraps.w, true));
    vec3 viewer = !viewer_is_ray ? normalize(-s.position) : -normalize(mat3(frame.view) * dir_w);
    // KHR_materials_specular's textures at their own coordinates (the factors' F0 without them).
    vec3 dielectric_f0 = material_dielectric_f0(
        m, sample_image(m.specular_images.x, texture_uv(m, 4, a.uv), m.specular_wraps.x, false),
        sample_image(m.specular_images.y, texture_uv(m, 5, a.uv), m.specular_wraps.y, true));
    s.radiance = shade_surface(g, emission, dielectric_f0, s.position, viewer);
    return s;
}

// The same for a view-space ray.
ShadedHit trace_and_shade(vec3 origin, vec3 dir, bool viewer_is_ray) {
    return trace_and_shade_w((frame.inv_view * vec4(origin, 1.0)).xyz, normalize(mat3(frame.inv_view) * dir),
                             viewer_is_ray);
}
