// variance_rays (seed 000 4.4's future work; FidelityFX SSSR's variance-guided extra
// rays): with Settings.adaptive_rays a pixel traces ceil(rays_per_pixel * roughness) rays. This
// pass measures, per trace pixel, how much the first pass's rays disagree over its 3x3
// neighbourhood (relative standard deviation of the luminance each ray brings) and lists the
// pixels at or above Settings.variance_threshold that traced fewer than rays_per_pixel rays. A
// second trace (trace_linear_extra / trace_hiz_extra, trace_pass.h) then traces the rays
// adaptive_rays left out for the listed pixels only, by indirect dispatch, into the ray slots
// the resolve already reads: the resolve is unchanged and averages every ray with the weight
// it was drawn with.
//   inputs : lit, linear_depth, gbuffer.*, rays.hit, rays.sample, rays.direction
//   outputs: variance (R32F at the trace resolution: the relative standard deviation, -1 where
//            the pixel traced no ray), the buffer extra_ray_list (classify.h's layout)
#pragma once

#include "passes/classify.h"

namespace ssr {

class VarianceRaysPass : public ClassifyPass {
public:
    std::string name() const override { return "variance_rays"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override {
        // Rays where the first trace's neighbourhood disagrees (FidelityFX SSSR).
        return f.reflections && s.method != TraceMethod::Bvh && s.variance_rays && s.adaptive_rays;
    }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override {
        return {"rays.hit", "rays.sample", "rays.direction", "lit", "linear_depth",
                "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"};
    }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{"variance", GL_R32F, s.trace_width(), s.trace_height(), 0, 1}};
    }
    // The list of the pixels that get extra rays, in the ray list's layout.
    std::vector<std::string> buffer_inputs(const RenderSettings&, const FrameFacts&) const override { return {}; }
    std::vector<std::string> buffer_outputs(const RenderSettings&, const FrameFacts&) const override {
        return {"extra_ray_list"};
    }
    void execute(FrameContext& ctx) override;
    // The list's counters (frame.stats): variance_pixels (pixels listed for extra rays),
    // extra_rays (rays the second trace generated), extra_depth_fetches.
    std::map<std::string, double> extra_counters() const;
    void report(const RenderSettings&, std::map<std::string, double>& stats) const override {
        for (const auto& [k, v] : extra_counters()) stats[k] = v;
    }
};

}  // namespace ssr
