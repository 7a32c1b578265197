// svgf_atrous: the SVGF denoiser's edge-avoiding a-trous wavelet filter, Settings.svgf_iterations
// iterations with taps 2^i pixels apart, guided by depth, normal and luminance variance
// (Schied et al. 2017, 4.3; seed 003; shaders/passes/svgf_atrous.comp). One pass, timed as a whole.
//   inputs : svgf.variance, svgf.guide
//   outputs: reflection.denoised (RGBA32F: rgb denoised reflection, a variance), svgf.atrous
//            (the iterations' ping-pong partner)
// The composite and frame.reflection read reflection.denoised.
#pragma once

#include "render/render_pass.h"

namespace ssr {

class SvgfAtrousPass : public RenderPass {
public:
    std::string name() const override { return "svgf_atrous"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return f.reflections && s.denoise == Denoise::Svgf; }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override {
        return {"svgf.variance", "svgf.guide"};
    }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{"reflection.denoised", GL_RGBA32F, s.width, s.height, 0, 1},
                {"svgf.atrous", GL_RGBA32F, s.width, s.height, 0, 1}};
    }
    void execute(FrameContext& ctx) override;
};

}  // namespace ssr
