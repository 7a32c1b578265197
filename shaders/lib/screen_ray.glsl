// A view-space ray segment in screen space: both tracers start here. Needs frame_uniforms
// and ssr_settings.

// Length of the ray from `origin` along `dir` (view space) that stays in front of the near
// plane, at most `max_len`.
float ray_length_in_front_of_near(vec3 origin, vec3 dir, float max_len) {
    float near_z = -frame.clip.x;
    if (origin.z + dir.z * max_len > near_z) max_len = (near_z - origin.z) / dir.z * 0.999;
    return max(max_len, 0.0);
}

// Window position of a view-space point: xy in pixels (level-0 texels of the G-buffer,
// GL orientation), z the homogeneous w (= positive view depth).
vec3 view_to_pixel(vec3 p) {
    vec4 c = frame.proj * vec4(p, 1.0);
    return vec3((c.xy / c.w * 0.5 + 0.5) * frame.viewport.xy, c.w);
}

// The parameter in [0, 1] where the screen segment a -> b leaves the rectangle [0, size].
float screen_exit(vec2 a, vec2 b, vec2 size) {
    vec2 d = b - a;
    float t = 1.0;
    if (d.x > 0.0) t = min(t, (size.x - a.x) / d.x);
    if (d.x < 0.0) t = min(t, -a.x / d.x);
    if (d.y > 0.0) t = min(t, (size.y - a.y) / d.y);
    if (d.y < 0.0) t = min(t, -a.y / d.y);
    return clamp(t, 0.0, 1.0);
}

// Fades of a hit (seed 002, 4.6.1): near the image border, for rays toward the camera, and
// with travel distance. 1 = keep the hit, 0 = use the environment.
float hit_fade(vec2 hit_pixel, vec3 origin, vec3 dir, vec3 hit_view) {
    float fade = 1.0;
    if (ssr.fade_border > 0.0) {
        vec2 uv = hit_pixel * frame.viewport.zw;
        float edge = min(min(uv.x, 1.0 - uv.x) * frame.viewport.x, min(uv.y, 1.0 - uv.y) * frame.viewport.y);
        fade *= clamp(edge / (ssr.fade_border * min(frame.viewport.x, frame.viewport.y)), 0.0, 1.0);
    }
    float toward_camera = dot(dir, normalize(-origin));
    if (ssr.fade_camera_end > ssr.fade_camera_start)
        fade *= 1.0 - smoothstep(ssr.fade_camera_start, ssr.fade_camera_end, toward_camera);
    if (ssr.fade_distance_start > 0.0 && ssr.fade_distance_end > ssr.fade_distance_start)
        fade *= 1.0 - smoothstep(ssr.fade_distance_start, ssr.fade_distance_end, distance(origin, hit_view));
    return fade;
}
