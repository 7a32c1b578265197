// reproject: every pixel's position in the previous frame of a sequence and whether its
// history is valid (seed 002, 4.6.5 and 4.7.4; shaders/passes/reproject.comp).
//   inputs : linear_depth, gbuffer.normal, gbuffer.material (+ the previous frame's, from the
//            sequence's history)
//   outputs: reprojection (RGBA32F: previous window position in pixels, valid, reason)
// In the chain when a temporal technique is on (Settings.temporal_reflections).
#pragma once

#include "render/render_pass.h"

namespace ssr {

class ReprojectPass : public RenderPass {
public:
    std::string name() const override { return "reproject"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override {
        // Whenever a temporal technique that reprojects is on (the thesis's TAA blends at the
        // same pixel and needs none).
        return s.temporal_reflections || s.taa == TaaMode::Clamped || s.bounces == Bounces::History ||
               s.temporal_ray_reuse || (f.reflections && s.denoise == Denoise::Svgf);
    }
    std::vector<std::string> history_inputs(const RenderSettings&) const override {
        return {"linear_depth", "gbuffer.normal", "gbuffer.material"};
    }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override { return {"linear_depth", "gbuffer.normal", "gbuffer.material"}; }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{"reprojection", GL_RGBA32F, s.width, s.height, 0, 1}};
    }
    void execute(FrameContext& ctx) override;
};

}  // namespace ssr
