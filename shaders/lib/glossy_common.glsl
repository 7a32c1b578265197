// What the glossy methods (cone_trace, blur_mips) share: the pixel's one mirror ray, read
// back from the trace pass, and the pre-convolved colour. Needs frame_uniforms,
// depth_convention, ssr_settings, gbuffer, environment; the including pass binds the
// samplers named below.

// The full-resolution pixel whose surface a trace pixel's ray starts from (as trace_common).
ivec2 glossy_origin_pixel(ivec2 q) {
    return min(q * ssr.downscale + ssr.downscale / 2, ivec2(frame.viewport.xy) - 1);
}

vec3 glossy_environment(vec3 dir_view) {
    return environment_radiance(normalize(mat3(frame.inv_view) * dir_view));
}

// Colour of a premultiplied (rgb * coverage, coverage) pre-convolved texel: the mean over
// the covered pixels it averages; `coverage` receives a.
vec3 unpremultiply(vec4 c, out float coverage) {
    coverage = c.a;
    return c.a > 1e-6 ? c.rgb / c.a : vec3(0.0);
}
