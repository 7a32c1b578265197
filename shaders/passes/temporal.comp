#version 450 core
// temporal (seed 002, 4.7.4; seed 000, 4.4): accumulates the resolved reflection over the
// frames of a sequence. Where the reprojection kept the history, the previous accumulated
// reflection is fetched at the pixel's previous position (bilinear) and blended with this
// frame's: c = c_prev + (c_cur - c_prev) / n, n = min(n_prev + 1, max_history) frames. Up to
// max_history frames this is the plain mean of every frame's samples (each frame draws new
// rays: the sequence changes the seed); beyond it an exponential average whose current frame
// weighs 1 / max_history. Rejected history falls back to the current frame (n = 1).
//   output (RGBA32F): rgb accumulated reflection, a history length n in frames
#include "../lib/frame_uniforms.glsl"
#include "../lib/ycocg.glsl"
#include "../lib/history_fetch.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = TEXTURE_REFLECTION) uniform sampler2D u_reflection;
layout(binding = TEXTURE_REPROJECTION) uniform sampler2D u_reprojection;
layout(binding = TEXTURE_PREVIOUS_REFLECTION_TEMPORAL) uniform sampler2D u_history;  // previous reflection.temporal

layout(binding = IMAGE_REFLECTION_TEMPORAL, rgba32f) writeonly uniform image2D o_accumulated;

uniform int u_has_history;
uniform int u_max_history;
// Neighbourhood variance clamp (Salvi 2016; the modern counterpart of seed 002 4.7.4's
// rejection): the history is clamped to this frame's 3x3 mean +- gamma sigma in YCoCg. It
// catches what depth and normal tests cannot: a reflection that moved across a surface that
// did not (reflections are view-dependent), i.e. the ghost trails of a moving camera. 0: off.
uniform float u_clamp_gamma;

void main() {
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) return;
    vec3 current = texelFetch(u_reflection, pixel, 0).rgb;
    vec4 r = texelFetch(u_reprojection, pixel, 0);
    vec3 result = current;
    float n = 1.0;
    if (u_has_history != 0 && r.z > 0.5) {
        vec4 h = history_bilinear(u_history, r.xy, size);
        if (u_clamp_gamma > 0.0) {
            vec3 m1 = vec3(0.0), m2 = vec3(0.0);
            for (int dy = -1; dy <= 1; ++dy) {
                for (int dx = -1; dx <= 1; ++dx) {
                    vec3 c = rgb_to_ycocg(texelFetch(u_reflection, clamp(pixel + ivec2(dx, dy), ivec2(0), size - 1), 0).rgb);
                    m1 += c;
                    m2 += c * c;
                }
            }
            m1 /= 9.0;
            vec3 sigma = sqrt(max(m2 / 9.0 - m1 * m1, 0.0));
            h.rgb = ycocg_to_rgb(clamp(rgb_to_ycocg(h.rgb), m1 - u_clamp_gamma * sigma, m1 + u_clamp_gamma * sigma));
        }
        n = min(floor(h.a + 0.5) + 1.0, float(u_max_history));
        n = max(n, 1.0);
        result = h.rgb + (current - h.rgb) / n;
    }
    imageStore(o_accumulated, pixel, vec4(result, n));
}
