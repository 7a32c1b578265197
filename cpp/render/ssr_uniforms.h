// Screen-space reflection settings as the shaders see them (uniform buffer binding 4,
// std140 with scalars only). Mirrored field by field in shaders/lib/ssr_settings.glsl.
#pragma once

#include <cstdint>

namespace ssr {

constexpr int kSsrSettingsBinding = 4;

struct SsrUniforms {
    int32_t trace_width, trace_height, downscale, rays_per_pixel;
    int32_t sampling, noise, hammersley;
    uint32_t seed;
    int32_t layers, max_steps;
    float stride, jitter;
    float max_distance, origin_bias, thickness, thickness_scale;
    int32_t thickness_mode, refine_steps, hiz_start_level, hiz_stop_level;
    int32_t hiz_max_level, hiz_linear_steps, hiz_use_max;
    float hiz_crossing_offset;
    float fade_border, fade_camera_start, fade_camera_end, fade_distance_start;
    float fade_distance_end, roughness_cutoff, edge_depth_sigma, edge_normal_power;
    int32_t reuse_radius, reuse_weighting, edge_aware, cone_max_samples;
    float cone_level_bias;
    int32_t cone_remainder, cone_stretch, pad0;
};
static_assert(sizeof(SsrUniforms) == 40 * 4, "std140 layout of SsrUniforms");

struct RenderSettings;
SsrUniforms ssr_uniforms(const RenderSettings& s);

}  // namespace ssr
