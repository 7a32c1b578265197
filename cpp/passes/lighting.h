// lighting: shades every G-buffer layer with direct light, the shadow map and a constant
// ambient term (shaders/lib/shading.glsl), and writes each layer's linear view depth.
//   inputs : gbuffer.depth, gbuffer.albedo, gbuffer.normal, gbuffer.material, shadow_map
//            (when shadows are on)
//   outputs: lit (RGBA16F array: radiance per layer), linear_depth (R32F array: positive
//            view-space depth per layer; the far-plane distance where nothing is covered)
#pragma once

#include "render/render_pass.h"

namespace ssr {

class LightingPass : public RenderPass {
public:
    explicit LightingPass(bool shadows) : shadows_(shadows) {}
    std::string name() const override { return "lighting"; }
    std::vector<std::string> inputs() const override;
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override;
    void execute(FrameContext& ctx) override;

private:
    bool shadows_;
};

}  // namespace ssr
