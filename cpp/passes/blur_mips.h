// blur_mips: the engines' glossy baseline (seed 004 "Glossy", "Mipmap Generation";
// shaders/passes/blur_mips.comp): one mirror ray per pixel, and the pre-convolved colour at
// its hit, at the mip level of the GGX cone's footprint there (roughness and hit distance).
//   inputs : rays.hit, rays.sample, rays.direction, lit, linear_depth, gbuffer.albedo,
//            gbuffer.normal, gbuffer.material, lit_preconvolved
//   outputs: reflection (RGBA16F, full resolution)
// Runs for glossy="blur_mips", in place of the resolve.
#pragma once

#include "render/render_pass.h"

namespace ssr {

class BlurMipsPass : public RenderPass {
public:
    std::string name() const override { return "blur_mips"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return f.reflections && s.glossy == Glossy::BlurMips; }  // replaces the resolve
    // The textures its shader samples, bound by name (NamedUnits, passes/compute.h); with specular
    // occlusion also the unresolved rays' estimate (rays.radiance).
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override;
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{"reflection", GL_RGBA16F, s.width, s.height, 0, 1}};
    }
    void execute(FrameContext& ctx) override;
};

}  // namespace ssr
