// Reflection rays of a G-buffer pixel (seed 000, 2.3.4 steps 1-3): two random numbers per
// ray (plus a Hammersley point), a direction from the chosen sampling, and the weight and
// pdf the resolve needs. Needs frame_uniforms, ssr_settings, random, brdf, ggx_sampling,
// gbuffer.

struct ReflectionRay {
    vec3 origin;   // view space, biased off the surface along its normal
    vec3 dir;      // view space, unit length; 0 when the surface traces no ray at all
    float weight;  // 0: no ray (not reflective, too rough, or an invalid sample)
    float pdf;
};

// A pass may compile the noise and the Hammersley switch in (the trace passes do: llvmpipe
// computed both hashes for every ray); the values must be the settings block's.
#ifndef RAY_NOISE
#define RAY_NOISE ssr.noise
#endif
#ifndef RAY_HAMMERSLEY
#define RAY_HAMMERSLEY ssr.hammersley
#endif

// Two uniform numbers for ray `r` of trace pixel `q`.
vec2 ray_random(ivec2 q, int r, GSample g) {
    vec2 u;
    if (RAY_NOISE == NOISE_THESIS_HASH) {
        // Seeded by camera position, pixel position and surface normal, as the thesis does.
        vec2 s = vec2(q) + frame.inv_view[3].xy * 0.61 + g.normal.xy * 17.3 + float(ssr.seed % 1000u) * 0.173;
        s += float(r) * vec2(3.31, 7.77);
        u = vec2(thesis_hash(s), thesis_hash(s.yx + vec2(19.19, 5.07)));
    } else {
        uint h = pcg_hash(uint(q.x) ^ pcg_hash(uint(q.y) ^ pcg_hash(ssr.seed)));
        u = vec2(unit_float(pcg_hash(h + 2u * uint(r))), unit_float(pcg_hash(h + 2u * uint(r) + 1u)));
    }
    if (RAY_HAMMERSLEY != 0) u = fract(u + hammersley(uint(r), uint(ssr.rays_per_pixel)));
    return u;
}

// Whether a layer-0 pixel reflects at all: a surface with reflectivity, smooth enough.
bool is_reflective(GSample g) {
    return g.covered && g.reflectivity > 0.0 && g.roughness <= ssr.roughness_cutoff;
}

#ifndef ADAPTIVE_RAYS
#define ADAPTIVE_RAYS 0
#endif

// The rays a pixel traces (Settings.adaptive_rays; seed 000 4.4's future work): with
// adaptive rays they follow the perceptual roughness within the user's maximum, one for a
// mirror (every GGX sample of alpha 0 is the mirror direction), the maximum at roughness 1.
// Rays past the count get weight 0, which the resolve's weighted mean leaves out: each pixel
// still averages its rays with the weights they were drawn with.
int adaptive_ray_count(float roughness) {
    return clamp(int(ceil(float(ssr.rays_per_pixel) * roughness)), 1, ssr.rays_per_pixel);
}

int rays_for_roughness(float roughness) {
#if ADAPTIVE_RAYS
    return adaptive_ray_count(roughness);
#else
    return ssr.rays_per_pixel;
#endif
}

// A pass may compile its sampling method in (the trace passes do, so that the sampler's branch
// on the method folds away); the value must be the settings block's.
#ifndef RAY_SAMPLING
#define RAY_SAMPLING ssr.sampling
#endif

ReflectionRay generate_ray(GSample g, vec3 p_view, ivec2 q, int r) {
    ReflectionRay ray;
    ray.origin = p_view;
    // Direction 0: this surface traces no ray at all ("no ray", stored as zeros).
    ray.dir = vec3(0.0);
    ray.weight = 0.0;
    ray.pdf = 0.0;
    vec3 v = normalize(-p_view);
    vec3 n = g.normal;
    if (!is_reflective(g) || dot(n, v) <= 1e-4) return ray;  // no ray from surfaces seen edge-on or from behind
    ray.dir = vec3(0.0, 0.0, -1.0);  // a slot of a pixel that traces, weight 0
    if (r >= rays_for_roughness(g.roughness)) return ray;  // adaptive rays: this pixel needs fewer
    mat3 tbn = frame_from_normal(n);
    vec3 v_local = transpose(tbn) * v;
    float alpha = g.roughness * g.roughness;  // GGX alpha from perceptual roughness (glTF)
    BrdfSample s = sample_reflection(v_local, alpha, RAY_SAMPLING, ray_random(q, r, g));
    ray.dir = normalize(tbn * s.l);
    ray.weight = s.weight;
    ray.pdf = s.pdf;
    ray.origin = p_view + n * (ssr.origin_bias * -p_view.z);
    return ray;
}
