// specular_occlusion (Settings.specular_occlusion; shaders/passes/specular_occlusion.comp): what
// a reflection ray screen space did not resolve brings, the environment weighted by the share
// of the ray (or of the lobe, for glossy "cone" and "blur_mips") the scene leaves open, the
// rest the radiance of what blocks it. Estimators: "horizon" (GTSO, Jimenez et al. 2016: the
// visibility cone of horizon-based occlusion over layer 0's depth) and "exit" (where the ray left
// the screen: the deep G-buffer's surfaces at its exit pixel and whether it runs into them).
//   inputs : linear_depth, gbuffer.normal, gbuffer.material, lit, rays.hit, rays.sample,
//            rays.direction, gbuffer.albedo
//   outputs: rays.radiance (as fallback_probes: rgb the radiance, a -1 for an unresolved ray,
//            -2 for a resolved one)
// Runs after the tracer with fallback "environment" (the fallbacks "bvh" and "probes" own
// rays.radiance) and specular_occlusion other than "off". Counts the unresolved rays and the
// occluded ones (visibility below 1/2) for Frame.stats.
#pragma once

#include <map>
#include <string>

#include "core/gl_resources.h"
#include "render/render_pass.h"

namespace ssr {

class SpecularOcclusionPass : public RenderPass {
public:
    std::string name() const override { return "specular_occlusion"; }
    std::vector<std::string> inputs() const override {
        return {"linear_depth", "gbuffer.normal", "gbuffer.material", "lit", "rays.hit", "rays.sample",
                "rays.direction", "gbuffer.albedo"};
    }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{"rays.radiance", GL_RGBA32F, s.trace_width(), s.trace_height(), s.traced_rays(), 1}};
    }
    void execute(FrameContext& ctx) override;

    // Whether the chain runs the pass for these settings.
    static bool enabled(const RenderSettings& s);
    // frame.stats: occluded_misses, unresolved_rays of the last run.
    std::map<std::string, double> counters() const;

private:
    Buffer counters_;
};

}  // namespace ssr
