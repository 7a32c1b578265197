// hiz_build: the min-max Hi-Z pyramid of every G-buffer layer (seed 002, 4.4.1, 4.5.1).
//   inputs : gbuffer.depth, gbuffer.material (coverage)
//   outputs: hiz (RG32F array of Settings.layers layers, full mip chain: level l holds, per
//            cell, the (min, max) screen depth of its covered level-0 pixels)
// One compute dispatch per level; odd-sized levels fold their last row/column into the
// last cell. Runs only for method="hiz".
#pragma once

#include "render/render_pass.h"

namespace ssr {

class HizBuildPass : public RenderPass {
public:
    std::string name() const override { return "hiz_build"; }
    std::vector<std::string> inputs() const override { return {"gbuffer.depth", "gbuffer.material"}; }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{"hiz", GL_RG32F, s.width, s.height, s.layers, 0}};
    }
    void execute(FrameContext& ctx) override;
    // Layers the last run built (frame.stats["hiz_layers_built"], issue 11).
    int layers_built() const { return layers_built_; }

private:
    int layers_built_ = 0;
};

}  // namespace ssr
