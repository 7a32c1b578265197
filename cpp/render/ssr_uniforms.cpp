#include "render/ssr_uniforms.h"

#include "render/settings.h"

namespace ssr {

SsrUniforms ssr_uniforms(const RenderSettings& s) {
    SsrUniforms su{};
    su.trace_width = s.trace_width();
    su.trace_height = s.trace_height();
    su.downscale = s.downscale;
    su.rays_per_pixel = s.rays_per_pixel;
    su.sampling = int(s.sampling);
    su.noise = int(s.noise);
    su.hammersley = s.hammersley;
    su.seed = s.seed;
    su.layers = s.layers;
    su.max_steps = s.max_steps;
    su.stride = s.stride;
    su.jitter = s.jitter;
    su.max_distance = s.max_distance;
    su.origin_bias = s.origin_bias;
    su.thickness = s.thickness;
    su.thickness_scale = s.thickness_scale;
    su.thickness_mode = int(s.thickness_mode);
    su.refine_steps = s.refine_steps;
    su.hiz_start_level = s.hiz_start_level;
    su.hiz_stop_level = s.hiz_stop_level;
    su.hiz_max_level = s.hiz_max_level;
    su.hiz_linear_steps = s.hiz_linear_steps;
    su.hiz_use_max = s.hiz_use_max;
    su.hiz_crossing_offset = s.hiz_crossing_offset;
    su.fade_border = s.fade_border;
    su.fade_camera_start = s.fade_camera_start;
    su.fade_camera_end = s.fade_camera_end;
    su.fade_distance_start = s.fade_distance_start;
    su.fade_distance_end = s.fade_distance_end;
    su.roughness_cutoff = s.roughness_cutoff;
    su.edge_depth_sigma = s.edge_depth_sigma;
    su.edge_normal_power = s.edge_normal_power;
    su.reuse_radius = s.reuse_radius;
    su.reuse_weighting = int(s.reuse_weighting);
    su.edge_aware = s.edge_aware;
    su.cone_max_samples = s.cone_max_samples;
    su.cone_level_bias = s.cone_level_bias;
    su.cone_remainder = int(s.cone_remainder);
    su.cone_stretch = s.cone_stretch;
    if (s.glossy != Glossy::Stochastic) {  // one mirror ray per pixel; the cone or the mip blurs it
        su.rays_per_pixel = 1;
        su.sampling = int(Sampling::Mirror);
    }
    return su;
}

}  // namespace ssr
