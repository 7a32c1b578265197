// svgf_variance: the SVGF denoiser's luminance variance estimate, temporal from the moments or,
// below 4 frames of history, spatial over a depth- and normal-guided 7x7 neighbourhood
// (Schied et al. 2017, 4.2; seed 003; shaders/passes/svgf_variance.comp).
//   inputs : svgf.accumulated, svgf.moments, linear_depth, gbuffer.normal, gbuffer.material
//   outputs: svgf.variance (RGBA32F: rgb colour, a luminance variance), svgf.guide (RGBA32F:
//            normal, depth and whether the pixel is filtered, for svgf_atrous's taps)
#pragma once

#include "render/render_pass.h"

namespace ssr {

class SvgfVariancePass : public RenderPass {
public:
    std::string name() const override { return "svgf_variance"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return f.reflections && s.denoise == Denoise::Svgf; }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override {
        return {"svgf.accumulated", "svgf.moments", "linear_depth", "gbuffer.normal", "gbuffer.material"};
    }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{"svgf.variance", GL_RGBA32F, s.width, s.height, 0, 1},
                {"svgf.guide", GL_RGBA32F, s.width, s.height, 0, 1}};
    }
    void execute(FrameContext& ctx) override;
};

}  // namespace ssr
