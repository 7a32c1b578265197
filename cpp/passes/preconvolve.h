// preconvolve: the pre-convolved colour pyramid of every lit G-buffer layer for the glossy
// methods (seed 002, 4.4.4 and 4.5.4; seed 004 "Mipmap Generation"; shaders/passes/preconvolve.comp).
//   inputs : lit, gbuffer.material (coverage)
//   outputs: lit_preconvolved (RGBA32F array of Settings.layers layers, full mip chain: rgb the
//            lit colour premultiplied by coverage, a the coverage; level n is level n-1
//            blurred by the chapter's normalised 7-tap Gaussian and reduced to GL's mip size),
//            preconvolve.scratch (RGBA32F: the x-blurred, x-reduced level between the passes)
// Float32 so that every level keeps level 0's coverage-weighted mean to float precision
// (half floats would round the coarse levels by up to 2.4e-4). Runs for glossy="cone" and
// glossy="blur_mips".
#pragma once

#include "render/render_pass.h"

namespace ssr {

class PreconvolvePass : public RenderPass {
public:
    std::string name() const override { return "preconvolve"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return f.reflections && s.glossy != Glossy::Stochastic; }  // seed 002, 4.4.4
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override { return {"lit", "gbuffer.material"}; }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{"lit_preconvolved", GL_RGBA32F, s.width, s.height, s.layers, 0},
                {"preconvolve.scratch", GL_RGBA32F, s.width, s.height, s.layers, 1}};
    }
    void execute(FrameContext& ctx) override;
};

}  // namespace ssr
