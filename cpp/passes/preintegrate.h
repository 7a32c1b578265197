// preintegrate: hierarchical pre-integrated visibility of every G-buffer layer from the
// min-max Hi-Z (seed 002, 4.4.2 and Listing 4.4; shaders/passes/preintegrate.comp).
//   inputs : hiz, gbuffer.material (coverage)
//   outputs: visibility (R16F array of Settings.layers layers, full mip chain: 1 where a layer
//            covers a level-0 pixel, 0 where not; V_n = mean of the children's V_(n-1) times
//            the filled share of the cell's depth slab, so V_n <= V_(n-1) on average over
//            the finer cells of every cell)
// 16-bit float, "8 bits or better" (the chapter uses 8). Runs for glossy="cone".
#pragma once

#include "render/render_pass.h"

namespace ssr {

class PreintegratePass : public RenderPass {
public:
    std::string name() const override { return "preintegrate"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return f.reflections && s.glossy == Glossy::Cone; }  // seed 002, 4.4.2
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override { return {"hiz", "gbuffer.material"}; }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{"visibility", GL_R16F, s.width, s.height, s.layers, 0}};
    }
    void execute(FrameContext& ctx) override;
};

}  // namespace ssr
