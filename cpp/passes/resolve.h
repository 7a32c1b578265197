// resolve: ray results -> reflection colour per pixel, with neighbour ray reuse and
// edge-aware upsampling of downscaled rays (seed 000, 2.4 and 2.6; shaders/passes/resolve.comp).
//   inputs : rays.hit, rays.sample, rays.direction, lit, linear_depth, gbuffer.albedo,
//            gbuffer.normal, gbuffer.material
//            (+ rays.radiance with method or fallback "bvh", issue 12)
//   outputs: reflection (RGBA16F, full resolution; 0 where a pixel does not reflect)
#pragma once

#include "render/render_pass.h"

namespace ssr {

class ResolvePass : public RenderPass {
public:
    std::string name() const override { return "resolve"; }
    std::vector<std::string> inputs() const override {
        return {"rays.hit", "rays.sample", "rays.direction", "lit", "linear_depth",
                "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"};
    }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{"reflection", GL_RGBA16F, s.width, s.height, 0, 1}};
    }
    void execute(FrameContext& ctx) override;
};

}  // namespace ssr
