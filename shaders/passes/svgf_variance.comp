#version 450 core
// svgf_variance (Schied et al. 2017, 4.2; seed 003 "Implementing a denoiser", step 2): the
// luminance variance each pixel's a-trous weights trust, Var = E[l^2] - E[l]^2 from the
// accumulated moments. Where fewer than 4 frames of history back them (a single render(), the
// first frames of a sequence, a disocclusion), the moments are first averaged over a 7x7
// neighbourhood weighted by depth and normal (the paper's spatial fallback), so the filter
// does not mistake one sample's luminance for a clean signal. The variance handed on is that of
// the accumulated mean, E[l^2] - E[l]^2 over n frames divided by n: the noise left in the colour
// the wavelets filter shrinks as the history grows, and so does their blur (the paper keeps the
// per-sample variance, which over-blurs a static camera's converging image).
//   outputs: svgf.variance (RGBA32F: rgb accumulated colour, a luminance variance)
//            svgf.guide (RGBA32F: xyz normal, w linear depth, negated where the pixel is not
//            noisy): what the a-trous taps test, in one fetch instead of three
#include "../lib/frame_uniforms.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/svgf.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = TEXTURE_SVGF_ACCUMULATED) uniform sampler2D u_accumulated;
layout(binding = TEXTURE_SVGF_MOMENTS) uniform sampler2D u_moments;
layout(binding = TEXTURE_LINEAR_DEPTH) uniform sampler2DArray u_linear_depth;
layout(binding = TEXTURE_GBUFFER_NORMAL) uniform sampler2DArray u_normal;
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;

layout(binding = IMAGE_SVGF_VARIANCE, rgba32f) writeonly uniform image2D o_variance;
layout(binding = IMAGE_SVGF_GUIDE, rgba32f) writeonly uniform image2D o_guide;

uniform float u_sigma_depth;
uniform float u_sigma_normal;
uniform int u_mirror_sampling;

float depth_at(ivec2 p, ivec2 size) {
    return texelFetch(u_linear_depth, ivec3(clamp(p, ivec2(0), size - 1), 0), 0).r;
}

bool noisy_at(ivec2 p, out vec3 normal) {
    vec4 nr = texelFetch(u_normal, ivec3(p, 0), 0);
    vec4 mat = texelFetch(u_material, ivec3(p, 0), 0);
    normal = normalize(nr.xyz);
    return svgf_noisy(mat.g > 0.5, mat.r, nr.w, u_mirror_sampling != 0);
}

void main() {
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) return;
    vec4 color = texelFetch(u_accumulated, pixel, 0);
    vec4 m = texelFetch(u_moments, pixel, 0);
    vec3 n_p;
    bool noisy = noisy_at(pixel, n_p);
    float z = depth_at(pixel, size);
    imageStore(o_guide, pixel, vec4(n_p, noisy ? z : -max(z, 1e-30)));
    if (!noisy) {
        imageStore(o_variance, pixel, vec4(color.rgb, 0.0));
        return;
    }
    vec2 moments = m.xy;
    if (m.z < 4.0) {
        float z_p = depth_at(pixel, size);
        vec2 grad = svgf_depth_gradient(z_p, depth_at(pixel - ivec2(1, 0), size), depth_at(pixel + ivec2(1, 0), size),
                                        depth_at(pixel - ivec2(0, 1), size), depth_at(pixel + ivec2(0, 1), size));
        vec2 sum = vec2(0.0);
        float wsum = 0.0;
        for (int dy = -3; dy <= 3; ++dy) {
            for (int dx = -3; dx <= 3; ++dx) {
                ivec2 q = pixel + ivec2(dx, dy);
                if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
                vec3 n_q;
                if (!noisy_at(q, n_q)) continue;
                // Depth and normal only: luminance is what is being estimated.
                float w = svgf_weight(z_p, depth_at(q, size), abs(dot(grad, vec2(dx, dy))), u_sigma_depth, n_p, n_q,
                                      u_sigma_normal, 0.0, 0.0, 1.0);
                sum += w * texelFetch(u_moments, q, 0).xy;
                wsum += w;
            }
        }
        moments = sum / max(wsum, 1e-10);
    }
    float variance = max(moments.y - moments.x * moments.x, 0.0) / max(m.z, 1.0);
    imageStore(o_variance, pixel, vec4(color.rgb, variance));
}
