// reproject_reflection: where each pixel's reflection was in the previous frame of a sequence,
// by the motion of what it reflects (Settings.reflection_reprojection "hit"; hit-point or
// parallax-corrected reprojection: Stachowiak 2015, FidelityFX SSSR; seed 002, 4.6.5;
// shaders/passes/reproject_reflection.comp). A reflection is not where its surface was: the
// reflected point lies behind the mirror at the hit distance, and moves with the hit's object,
// the mirror's and the camera.
//   inputs : rays.hit, rays.sample, rays.direction, linear_depth, gbuffer.normal,
//            gbuffer.material, reprojection (+ rays.radiance where the rays bring it: a hit
//            distance) and the previous frame's gbuffer.normal, gbuffer.material and
//            reflection.hits
//   outputs: reprojection.reflection (RGBA32F, the reprojection texture's layout: xy previous
//            position, z valid, w reason), reflection.hits (RGBA32F: what the pixel's reflection
//            shows, accumulated like it: the share of its rays' weight that hit and their
//            virtual depth, camera to surface plus hit distance; the rejection's history)
// In the chain when the reflection's temporal passes (temporal, svgf_temporal) run with
// reflection_reprojection "hit"; they then read reprojection.reflection instead of reprojection.
#pragma once

#include "render/render_pass.h"
#include "passes/reproject.h"

namespace ssr {

class ReprojectReflectionPass : public RenderPass {
public:
    // The reprojection the reflection's temporal passes read.
    static std::string reprojection(const RenderSettings& s) {
        return s.reflection_reprojection == ReflectionReprojection::Hit ? "reprojection.reflection" : "reprojection";
    }
    std::string name() const override { return "reproject_reflection"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override {
        return f.reflections && s.reflection_reprojection == ReflectionReprojection::Hit &&
               (s.temporal_reflections || s.denoise == Denoise::Svgf);
    }
    std::vector<std::string> history_inputs(const RenderSettings&) const override {
        return {"gbuffer.normal", "gbuffer.material", "reflection.hits"};
    }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override;
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {ReprojectPass::texture("reprojection.reflection", s),
                {"reflection.hits", GL_RGBA32F, s.width, s.height, 0, 1}};
    }
    void execute(FrameContext& ctx) override;
};

}  // namespace ssr
