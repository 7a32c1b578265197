// trace_hiz: hierarchical min-max traversal over every G-buffer layer (seed 002, 4.4.3,
// 4.5.3, 4.6.6, 4.6.7, 4.7.1; shaders/passes/trace_hiz.comp).
//   inputs : hiz_trace (hiz_build's atlas of the pyramid), linear_depth, gbuffer.albedo, gbuffer.normal, gbuffer.material
//   outputs: rays.hit, rays.sample, rays.direction (see trace_pass.h)
#pragma once

#include "passes/compute.h"
#include "passes/trace_pass.h"

namespace ssr {

class TraceHizPass : public TracePass {
public:
    using TracePass::TracePass;
    std::string name() const override { return extra() ? "trace_hiz_extra" : "trace_hiz"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return f.reflections && s.method == TraceMethod::Hiz && (!extra() || (s.variance_rays && s.adaptive_rays)); }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override {
        return {"hiz_trace", "linear_depth", "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"};
    }
    void execute(FrameContext& ctx) override {
        NamedUnits units{{"hiz_trace"}, {}};
        units.fetch(ctx.fetch_by_image(), {"hiz_trace"});
        run(ctx, "passes/trace_hiz.comp", {}, units);
    }
};

}  // namespace ssr
