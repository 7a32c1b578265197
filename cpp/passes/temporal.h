// temporal: accumulation of the resolved reflection over a sequence's frames (seed 002,
// 4.7.4; seed 000, 4.4; shaders/passes/temporal.comp).
//   inputs : reflection, reprojection (reprojection.reflection with reflection_reprojection "hit":
//            passes/reproject_reflection.h) (+ the previous frame's reflection.temporal)
//   outputs: reflection.temporal (RGBA32F: rgb accumulated reflection, a history length)
// In the chain when Settings.temporal_reflections is on and the frame traces reflections; the
// composite then reads reflection.temporal.
#pragma once

#include "passes/reproject_reflection.h"
#include "render/render_pass.h"

namespace ssr {

class TemporalPass : public RenderPass {
public:
    std::string name() const override { return "temporal"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return f.reflections && s.temporal_reflections; }  // when there is a reflection to accumulate
    std::vector<std::string> history_inputs(const RenderSettings&) const override { return {"reflection.temporal"}; }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override {
        return {"reflection", ReprojectReflectionPass::reprojection(s)};
    }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{"reflection.temporal", GL_RGBA32F, s.width, s.height, 0, 1}};
    }
    void execute(FrameContext& ctx) override;
};

}  // namespace ssr
