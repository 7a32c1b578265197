#version 450 core
// variance_rays (FidelityFX SSSR's variance-guided extra rays; seed 000 4.4's future
// work): where the adaptive first pass's rays disagree over a trace pixel's 3x3 neighbourhood,
// list the pixel for a second trace of the rays adaptive_rays left out. The disagreement is the
// relative standard deviation (std / mean) of the luminance the neighbourhood's rays bring: the
// lit colour at a hit (faded toward the environment as the resolve fades it) or the
// environment. A spatial estimate of one frame (FidelityFX uses a temporal one); the choice of
// pixels only decides how many rays a pixel averages, each ray keeps its own weight.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/ssr_settings.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/brdf.glsl"
#include "../lib/random.glsl"
#include "../lib/ggx_sampling.glsl"
#include "../lib/ray_generation.glsl"
#include "../lib/environment.glsl"
#include "../lib/ray_list.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = TEXTURE_RAYS_HIT) uniform sampler2DArray u_hit;
layout(binding = TEXTURE_RAYS_SAMPLE) uniform sampler2DArray u_sample;
layout(binding = TEXTURE_RAYS_DIRECTION) uniform sampler2DArray u_direction;
layout(binding = TEXTURE_LIT) uniform sampler2DArray u_lit;
layout(binding = TEXTURE_LINEAR_DEPTH) uniform sampler2DArray u_linear_depth;
layout(binding = TEXTURE_GBUFFER_ALBEDO) uniform sampler2DArray u_albedo;
layout(binding = TEXTURE_GBUFFER_NORMAL) uniform sampler2DArray u_normal;
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;
layout(binding = IMAGE_VARIANCE, r32f) writeonly uniform image2D o_variance;

uniform float u_threshold;  // Settings.variance_threshold

float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

// The luminance ray r of trace pixel q brings (the resolve's radiance of a screen-space ray).
float ray_luminance(ivec2 q, int r) {
    vec4 hit = texelFetch(u_hit, ivec3(q, r), 0);
    vec3 dir = texelFetch(u_direction, ivec3(q, r), 0).xyz;
    vec3 c = environment_radiance(normalize(mat3(frame.inv_view) * dir));
    if (hit.z > 0.5) {
        ivec2 size = ivec2(frame.viewport.xy);
        c = mix(c, texelFetch(u_lit, ivec3(clamp(ivec2(hit.xy), ivec2(0), size - 1), int(hit.z) - 1), 0).rgb, hit.w);
    }
    return luminance(c);
}

void main() {
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    ivec2 trace_size = ivec2(ssr.trace_width, ssr.trace_height);
    if (any(greaterThanEqual(q, trace_size))) return;
    ivec2 p = min(q * ssr.downscale + ssr.downscale / 2, ivec2(frame.viewport.xy) - 1);  // origin_pixel
    GSample g = gbuffer_decode(texelFetch(u_albedo, ivec3(p, 0), 0), texelFetch(u_normal, ivec3(p, 0), 0),
                               texelFetch(u_material, ivec3(p, 0), 0));
    // Only a pixel that traced rays (weight > 0 for ray 0 or any other) can be given more.
    bool traced = false;
    for (int r = 0; r < ssr.rays_per_pixel; ++r) traced = traced || texelFetch(u_sample, ivec3(q, r), 0).x > 0.0;
    if (!traced) {
        imageStore(o_variance, q, vec4(-1.0));
        return;
    }
    float n = 0.0, sum = 0.0, sum2 = 0.0;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 o = q + ivec2(dx, dy);
            if (any(lessThan(o, ivec2(0))) || any(greaterThanEqual(o, trace_size))) continue;
            for (int r = 0; r < ssr.rays_per_pixel; ++r) {
                if (texelFetch(u_sample, ivec3(o, r), 0).x <= 0.0) continue;  // no ray in this slot
                float l = ray_luminance(o, r);
                n += 1.0;
                sum += l;
                sum2 += l * l;
            }
        }
    float mean = sum / n;
    float relative_std = sqrt(max(sum2 / n - mean * mean, 0.0)) / max(mean, 1e-6);
    imageStore(o_variance, q, vec4(relative_std));
    if (adaptive_ray_count(g.roughness) < ssr.rays_per_pixel && relative_std >= u_threshold) {
        uint i = atomicAdd(ray_list.count, 1u);
        ray_list.pixels[i] = pack_pixel(q);
        ray_list_open_group(i);
    }
}
