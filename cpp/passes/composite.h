// composite: the final image.
//   inputs : lit, gbuffer.material
//   outputs: color (RGBA32F, linear radiance)
// Layer 0's lit colour where a surface covers the pixel, the background elsewhere.
#pragma once

#include "render/render_pass.h"

namespace ssr {

class CompositePass : public RenderPass {
public:
    std::string name() const override { return "composite"; }
    std::vector<std::string> inputs() const override { return {"lit", "gbuffer.material"}; }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{"color", GL_RGBA32F, s.width, s.height, 0, 1}};
    }
    void execute(FrameContext& ctx) override;
};

}  // namespace ssr
