// What trace_linear and trace_hiz share: the ray textures they write, at the trace
// resolution (the image divided by Settings.downscale), one layer per ray of a pixel:
//   rays.hit       RGBA32F: hit position (pixels), hit layer (1-based, 0 = miss), fade
//   rays.sample    RGBA32F: weight, pdf, depth fetches spent, 1 if the pixel traced rays
//   rays.direction RGBA32F: view-space direction of the ray
#pragma once

#include <functional>

#include "passes/classify.h"
#include "passes/compute.h"
#include "render/render_pass.h"

namespace ssr {

class TracePass : public RenderPass {
public:
    // With Settings.skip the trace runs over classify's buffer ray_list. `extra`: the
    // variance-guided second trace (Settings.variance_rays, variance_rays.h): over the buffer
    // extra_ray_list always, only the rays adaptive_rays left out, into the textures the first
    // trace declared.
    explicit TracePass(bool extra = false) : extra_(extra) {}
    bool extra() const { return extra_; }
    // The list it runs over, if any.
    std::vector<std::string> buffer_inputs(const RenderSettings& s, const FrameFacts&) const override {
        if (extra_) return {"extra_ray_list"};
        if (s.skip) return {"ray_list"};
        return {};
    }
    std::string stage() const override { return extra_ ? "trace_extra" : "trace"; }
    // One of the ray textures: at the trace resolution, a layer per ray of a pixel.
    // rays.hit, rays.sample or rays.direction: a layer per traced ray at the trace resolution,
    // with what its channels mean (frame.rays).
    static ResourceDesc ray_texture(const std::string& name, const RenderSettings& s);
    // The ray textures, which this pass rewrites where classify runs before it (classify writes
    // the skipped pixels' "no ray" and the rays adaptive_rays leaves out) and the second trace
    // rewrites after the first.
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        if (extra_ || ClassifyPass::writes_rays(s)) return {};
        return {ray_texture("rays.hit", s), ray_texture("rays.sample", s), ray_texture("rays.direction", s)};
    }
    std::vector<std::string> rewrites(const RenderSettings& s, const FrameFacts&) const override {
        if (extra_ || ClassifyPass::writes_rays(s)) return {"rays.hit", "rays.sample", "rays.direction"};
        return {};
    }

protected:
    // Binds by name the G-buffer and the ray textures (ray_generation_units, passes/compute.h)
    // and the tracer's own `units` (its further inputs and images), runs the shader `stage` over
    // every (trace pixel, ray), or with Settings.skip over the classify pass's ray list only
    // (indirect dispatch).
    // `setup` (optional) is called with the program in use, before the dispatch (a user pass's
    // parameters).
    void run(FrameContext& ctx, const std::string& stage, const std::function<void(GLuint)>& setup = {},
             const NamedUnits& units = {});

private:
    bool extra_;
};

}  // namespace ssr
