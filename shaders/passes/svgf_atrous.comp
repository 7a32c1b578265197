#version 450 core
// svgf_atrous (Schied et al. 2017, 4.3; seed 003 "Implementing a denoiser", step 3): one
// iteration of the edge-avoiding a-trous wavelet filter, run svgf_iterations times with taps
// 2^i pixels apart. Each pixel averages a 5x5 B3-spline footprint of noisy reflective pixels,
// every tap weighted by depth, normal and luminance (shaders/lib/svgf.glsl, svgf_weight); the
// luminance term is scaled by the standard deviation of the pixel's variance, pre-blurred by a
// 3x3 Gaussian. The variance is filtered alongside with squared weights, so each iteration's
// luminance test tightens as the noise goes. Unlike the paper (4.3), no iteration's output
// becomes the next frame's colour history (svgf_temporal keeps its unfiltered accumulation):
// fed back, the blur of every frame accumulates into the static image (measured in README,
// "Hybrid reflections").
//   input : the previous iteration (svgf.variance first): RGBA32F rgb colour, a variance
//   output: this iteration's (reflection.denoised after the last), same layout
#include "../lib/frame_uniforms.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/svgf.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = TEXTURE_ATROUS_INPUT) uniform sampler2D u_input;
layout(binding = TEXTURE_SVGF_GUIDE) uniform sampler2D u_guide;  // svgf_variance: xyz normal, w depth (< 0: not noisy)

layout(binding = IMAGE_ATROUS_OUTPUT, rgba32f) writeonly uniform image2D o_output;

uniform int u_step;           // 2^iteration pixels between taps; 0: copy (svgf_iterations = 0)
uniform float u_sigma_depth;
uniform float u_sigma_normal;
uniform float u_sigma_luminance;

float depth_at(ivec2 p, ivec2 size) {
    return abs(texelFetch(u_guide, clamp(p, ivec2(0), size - 1), 0).w);
}

// One fetch per tap: the normal, the depth and whether the pixel is filtered at all.
bool noisy_at(ivec2 p, out vec3 normal, out float depth) {
    vec4 g = texelFetch(u_guide, p, 0);
    normal = g.xyz;
    depth = g.w;
    return g.w > 0.0;
}

void main() {
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) return;
    vec4 center = texelFetch(u_input, pixel, 0);
    vec3 n_p;
    float z_p;
    if (u_step == 0 || !noisy_at(pixel, n_p, z_p)) {
        imageStore(o_output, pixel, center);
        return;
    }
    // The variance the luminance test trusts: a 3x3 Gaussian of it (paper, eq. 5), over the
    // noisy neighbours only.
    float var_blur = 0.0, var_w = 0.0;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 q = pixel + ivec2(dx, dy);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            vec3 n_q;
            float z_q;
            if (!noisy_at(q, n_q, z_q)) continue;
            float k = (dx == 0 ? 0.5 : 0.25) * (dy == 0 ? 0.5 : 0.25);
            var_blur += k * texelFetch(u_input, q, 0).a;
            var_w += k;
        }
    }
    var_blur /= max(var_w, 1e-10);
    float luminance_scale = u_sigma_luminance * sqrt(max(var_blur, 0.0));

    vec2 grad = svgf_depth_gradient(z_p, depth_at(pixel - ivec2(1, 0), size), depth_at(pixel + ivec2(1, 0), size),
                                    depth_at(pixel - ivec2(0, 1), size), depth_at(pixel + ivec2(0, 1), size));
    float l_p = svgf_luminance(center.rgb);
    // The centre tap weighs h(0)^2 with every edge term 1.
    float w_c = svgf_b3(0) * svgf_b3(0);
    vec3 color = w_c * center.rgb;
    float variance = w_c * w_c * center.a;
    float wsum = w_c;
    for (int j = -2; j <= 2; ++j) {
        for (int i = -2; i <= 2; ++i) {
            if (i == 0 && j == 0) continue;
            ivec2 offset = ivec2(i, j) * u_step;
            ivec2 q = pixel + offset;
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            vec3 n_q;
            float z_q;
            if (!noisy_at(q, n_q, z_q)) continue;
            vec4 c = texelFetch(u_input, q, 0);
            float w = svgf_b3(i) * svgf_b3(j) *
                      svgf_weight(z_p, z_q, abs(dot(grad, vec2(offset))), u_sigma_depth, n_p, n_q,
                                  u_sigma_normal, l_p, svgf_luminance(c.rgb), luminance_scale);
            color += w * c.rgb;
            variance += w * w * c.a;
            wsum += w;
        }
    }
    imageStore(o_output, pixel, vec4(color / wsum, variance / (wsum * wsum)));
}
