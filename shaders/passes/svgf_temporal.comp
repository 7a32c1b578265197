#version 450 core
// svgf_temporal (Schied et al. 2017, 4.1; seed 003 "Implementing a denoiser", step 1): temporal
// accumulation of the resolved reflection's colour and of its luminance's first and second
// moments. The reproject pass (shaders/lib/reprojection.glsl, Settings.reject_*) says where
// each pixel was in the previous frame and whether its history belongs to the same surface;
// kept history is fetched bilinearly there and blended with weight 1/n, n = min(frames of
// history + 1, svgf_max_history): the plain mean up to the cap, then an exponential average
// (the paper's alpha = 0.2 is a cap of 5). The colour history is the previous frame's
// unfiltered accumulation, not the paper's first a-trous output (see svgf_atrous.comp).
// Noiseless pixels (shaders/lib/svgf.glsl) keep this frame's colour: they have nothing to average.
//   outputs: svgf.accumulated (RGBA32F: rgb colour, a history length n)
//            svgf.moments     (RGBA32F: x E[l], y E[l^2], z history length n)
#include "../lib/frame_uniforms.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/history_fetch.glsl"
#include "../lib/svgf.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = TEXTURE_REFLECTION) uniform sampler2D u_reflection;
layout(binding = TEXTURE_REPROJECTION) uniform sampler2D u_reprojection;  // xy previous position, z valid
layout(binding = TEXTURE_GBUFFER_NORMAL) uniform sampler2DArray u_normal;
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;
layout(binding = TEXTURE_PREVIOUS_SVGF_ACCUMULATED) uniform sampler2D u_history_color;    // previous svgf.accumulated
layout(binding = TEXTURE_PREVIOUS_SVGF_MOMENTS) uniform sampler2D u_history_moments;  // previous svgf.moments

layout(binding = IMAGE_SVGF_ACCUMULATED, rgba32f) writeonly uniform image2D o_accumulated;
layout(binding = IMAGE_SVGF_MOMENTS, rgba32f) writeonly uniform image2D o_moments;

uniform int u_has_history;
uniform int u_max_history;
uniform int u_mirror_sampling;

void main() {
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) return;
    vec3 color = texelFetch(u_reflection, pixel, 0).rgb;
    float l = svgf_luminance(color);
    vec2 moments = vec2(l, l * l);
    float n = 1.0;
    vec4 nr = texelFetch(u_normal, ivec3(pixel, 0), 0);
    vec4 mat = texelFetch(u_material, ivec3(pixel, 0), 0);
    bool noisy = svgf_noisy(mat.g > 0.5, mat.r, nr.w, u_mirror_sampling != 0);
    vec4 r = texelFetch(u_reprojection, pixel, 0);
    if (noisy && u_has_history != 0 && r.z > 0.5) {
        vec4 hm = history_bilinear(u_history_moments, r.xy, size);
        vec3 hc = history_bilinear(u_history_color, r.xy, size).rgb;
        n = clamp(floor(hm.z + 0.5) + 1.0, 1.0, float(u_max_history));
        float alpha = 1.0 / n;
        color = mix(hc, color, alpha);
        moments = mix(hm.xy, moments, alpha);
    }
    imageStore(o_accumulated, pixel, vec4(color, n));
    imageStore(o_moments, pixel, vec4(moments, n, 0.0));
}
