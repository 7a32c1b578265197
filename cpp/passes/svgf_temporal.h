// svgf_temporal: the SVGF denoiser's temporal accumulation of the reflection's colour and
// luminance moments (Schied et al. 2017, 4.1; seed 003; shaders/passes/svgf_temporal.comp).
//   inputs : reflection, reprojection (reprojection.reflection with reflection_reprojection "hit":
//            passes/reproject_reflection.h), gbuffer.normal, gbuffer.material (+ the previous
//            frame's svgf.accumulated and svgf.moments, from the sequence's history)
//   outputs: svgf.accumulated (RGBA32F: rgb colour, a history length),
//            svgf.moments (RGBA32F: E[l], E[l^2], history length)
// In the chain when Settings.denoise is "svgf" and the frame traces reflections.
#pragma once

#include "passes/reproject_reflection.h"
#include "render/render_pass.h"

namespace ssr {

class SvgfTemporalPass : public RenderPass {
public:
    std::string name() const override { return "svgf_temporal"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return f.reflections && s.denoise == Denoise::Svgf; }
    std::vector<std::string> history_inputs(const RenderSettings&) const override {
        return {"svgf.accumulated", "svgf.moments"};
    }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override {
        return {"reflection", ReprojectReflectionPass::reprojection(s), "gbuffer.normal", "gbuffer.material"};
    }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{"svgf.accumulated", GL_RGBA32F, s.width, s.height, 0, 1},
                {"svgf.moments", GL_RGBA32F, s.width, s.height, 0, 1}};
    }
    void execute(FrameContext& ctx) override;
};

}  // namespace ssr
