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

// The environment as a rough surface sees it: the GGX lobe's average over ENV_LOBE_SAMPLES
// fixed VNDF directions (a Hammersley set, the same for every pixel: smooth, deterministic),
// weighted as the stochastic rays are. A pre-filtered environment at this pixel's roughness
// computed by quadrature, for the constant, sky and map environments alike (the chapter's
// "cube-maps with the same roughness"). A mirror reads the mirror direction itself, exactly
// as the resolve does. Needs brdf, random, ggx_sampling.
const int ENV_LOBE_SAMPLES = 16;

vec3 glossy_environment_lobe(vec3 n, vec3 v, float roughness, vec3 mirror_dir) {
    float alpha = roughness * roughness;
    if (alpha < 1e-4) return glossy_environment(mirror_dir);
    mat3 tbn = frame_from_normal(n);
    vec3 v_local = transpose(tbn) * v;
    vec3 sum = vec3(0.0);
    float total = 0.0;
    for (int i = 0; i < ENV_LOBE_SAMPLES; ++i) {
        vec2 u = hammersley(uint(i), uint(ENV_LOBE_SAMPLES)) + vec2(0.5 / float(ENV_LOBE_SAMPLES), 0.0);
        BrdfSample s = sample_reflection(v_local, alpha, SAMPLING_VNDF, fract(u));
        if (s.weight <= 0.0) continue;
        sum += s.weight * glossy_environment(tbn * s.l);
        total += s.weight;
    }
    return total > 0.0 ? sum / total : glossy_environment(mirror_dir);
}

// What the pixel's unresolved mirror ray brings for the lobe: with SPECULAR_OCCLUSION, the
// specular_occlusion pass's estimate (rays.radiance at TEXTURE_RAYS_RADIANCE, a = -1; the environment
// weighted by the share of the lobe the scene leaves open), else the lobe's environment.
#if defined(SPECULAR_OCCLUSION) && SPECULAR_OCCLUSION
layout(binding = TEXTURE_RAYS_RADIANCE) uniform sampler2DArray u_ray_radiance;
#endif

vec3 glossy_unresolved(ivec2 q, vec3 n, vec3 v, float roughness, vec3 mirror_dir) {
#if defined(SPECULAR_OCCLUSION) && SPECULAR_OCCLUSION
    vec4 rr = texelFetch(u_ray_radiance, ivec3(q, 0), 0);
    if (rr.a > -1.5) return rr.rgb;
#endif
    return glossy_environment_lobe(n, v, roughness, mirror_dir);
}
