// taa: temporal anti-aliasing of the final image over a sequence's jittered frames
// (shaders/passes/taa.comp).
//   thesis : the thesis's two-frame blend (seed 000, 2.5, after Sousa): the mean of this frame's
//            colour and the previous frame's colour at the same pixel, no reprojection
//   clamped: the reprojected previous TAA output, clamped to the min/max box of this frame's
//            3x3 neighbourhood in YCoCg, blended with weight Settings.taa_history_weight
//   inputs : color (+ reprojection for clamped; + the previous frame's color or color.taa).
//            One object per mode, so that the thesis blend, which never reprojects, does not
//            make the chain run the reprojection pass.
//   outputs: color.taa (RGBA32F; Frame.color reads it when present)
#pragma once

#include "render/render_pass.h"

namespace ssr {

class TaaPass : public RenderPass {
public:
    // The thesis's TAA or the clamped one (Settings.taa): a define of one program (TAA_THESIS).
    std::string name() const override { return "taa"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return s.taa != TaaMode::Off; }
    std::vector<std::string> history_inputs(const RenderSettings& s) const override {
        return {s.taa == TaaMode::Thesis ? "color" : "color.taa"};
    }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override {
        return s.taa == TaaMode::Thesis ? std::vector<std::string>{"color"} : std::vector<std::string>{"color", "reprojection"};
    }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{"color.taa", GL_RGBA32F, s.width, s.height, 0, 1}};
    }
    void execute(FrameContext& ctx) override;
};

}  // namespace ssr
