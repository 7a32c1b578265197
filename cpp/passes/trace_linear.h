// trace_linear: McGuire & Mara's perspective-correct DDA over every G-buffer layer
// (seed 000, 2.3; shaders/passes/trace_linear.comp).
//   inputs : linear_depth, gbuffer.albedo, gbuffer.normal, gbuffer.material
//   outputs: rays.hit, rays.sample, rays.direction (see trace_pass.h)
#pragma once

#include "passes/trace_pass.h"

namespace ssr {

class TraceLinearPass : public TracePass {
public:
    using TracePass::TracePass;
    std::string name() const override { return extra() ? "trace_linear_extra" : "trace_linear"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return f.reflections && s.method == TraceMethod::Linear && (!extra() || (s.variance_rays && s.adaptive_rays)); }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override {
        return {"linear_depth", "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"};
    }
    void execute(FrameContext& ctx) override {
        run(ctx, "passes/trace_linear.comp");
    }
};

}  // namespace ssr
