#version 450 core
// taa: temporal anti-aliasing of the final image (cpp/passes/taa.h).
// TAA_THESIS 1: the thesis's two-frame blend (seed 000, 2.5): with the jitter alternating
// between two offsets, the image shown is the mean of this frame and the previous one at the
// same pixel (no reprojection: the ghosting the thesis mentions under motion).
// TAA_THESIS 0: clamped-history TAA: the previous output fetched at the pixel's reprojected
// position (bilinear), clamped to the YCoCg min/max box of this frame's 3x3 neighbourhood so
// that history the current frame cannot explain does not ghost, then blended as
// c = w h + (1 - w) c_cur with w = Settings.taa_history_weight; rejected history gives c_cur.
#include "../lib/frame_uniforms.glsl"
#include "../lib/ycocg.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = TEXTURE_COLOR) uniform sampler2D u_color;
#if !TAA_THESIS
layout(binding = TEXTURE_REPROJECTION) uniform sampler2D u_reprojection;
#endif
layout(binding = TEXTURE_PREVIOUS_COLOR) uniform sampler2D u_history;

layout(binding = IMAGE_COLOR_TAA, rgba32f) writeonly uniform image2D o_color;

uniform int u_has_history;
uniform float u_history_weight;


vec4 history_at(vec2 pos, ivec2 size) {
    vec2 t = pos - 0.5;
    ivec2 b = ivec2(floor(t));
    vec2 f = t - vec2(b);
    vec4 c00 = texelFetch(u_history, clamp(b, ivec2(0), size - 1), 0);
    vec4 c10 = texelFetch(u_history, clamp(b + ivec2(1, 0), ivec2(0), size - 1), 0);
    vec4 c01 = texelFetch(u_history, clamp(b + ivec2(0, 1), ivec2(0), size - 1), 0);
    vec4 c11 = texelFetch(u_history, clamp(b + ivec2(1, 1), ivec2(0), size - 1), 0);
    return mix(mix(c00, c10, f.x), mix(c01, c11, f.x), f.y);
}

void main() {
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) return;
    vec3 current = texelFetch(u_color, pixel, 0).rgb;
    vec3 result = current;
#if TAA_THESIS
    if (u_has_history != 0) result = 0.5 * (current + texelFetch(u_history, pixel, 0).rgb);
#else
    vec4 r = texelFetch(u_reprojection, pixel, 0);
    if (u_has_history != 0 && r.z > 0.5) {
        vec3 lo = vec3(1e30), hi = vec3(-1e30);
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                vec3 c = rgb_to_ycocg(texelFetch(u_color, clamp(pixel + ivec2(dx, dy), ivec2(0), size - 1), 0).rgb);
                lo = min(lo, c);
                hi = max(hi, c);
            }
        vec3 h = ycocg_to_rgb(clamp(rgb_to_ycocg(history_at(r.xy, size).rgb), lo, hi));
        result = mix(current, h, u_history_weight);
    }
#endif
    imageStore(o_color, pixel, vec4(result, 1.0));
}
