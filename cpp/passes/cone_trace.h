// cone_trace: glossy reflections by Hi-Z cone tracing (seed 002, 4.4.5 and 4.5.5;
// shaders/passes/cone_trace.comp). One mirror ray per pixel (traced by trace_hiz or
// trace_linear), then a screen-space cone marched through the pre-convolved colour and the
// pre-integrated visibility, weighted by the cone sphere's overlap with the Hi-Z.
//   inputs : rays.hit, rays.sample, rays.direction, lit, linear_depth, gbuffer.albedo,
//            gbuffer.normal, gbuffer.material, lit_preconvolved, visibility, hiz
//   outputs: reflection (RGBA16F, full resolution; what the resolve writes otherwise)
// Runs for glossy="cone", in place of the resolve.
#pragma once

#include "render/render_pass.h"

namespace ssr {

class ConeTracePass : public RenderPass {
public:
    std::string name() const override { return "cone_trace"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return f.reflections && s.glossy == Glossy::Cone; }  // replaces the resolve (seed 002, 4.4.5)
    // The textures its shader samples, bound by name (NamedUnits, passes/compute.h); with specular
    // occlusion also the unresolved rays' estimate (rays.radiance).
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override;
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{"reflection", GL_RGBA16F, s.width, s.height, 0, 1}};
    }
    void execute(FrameContext& ctx) override;
};

}  // namespace ssr
