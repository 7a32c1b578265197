// specular_occlusion (Settings.specular_occlusion; shaders/passes/specular_occlusion.comp): what
// a reflection ray screen space did not resolve brings, the environment weighted by the share
// of the ray (or of the lobe, for glossy "cone" and "blur_mips") the scene leaves open, the
// rest the radiance of what blocks it. Estimators: "horizon" (GTSO, Jimenez et al. 2016: the
// visibility cone of horizon-based occlusion over layer 0's depth) and "exit" (where the ray left
// the screen: the deep G-buffer's surfaces at its exit pixel and whether it runs into them).
//   inputs : linear_depth, gbuffer.normal, gbuffer.material, lit, rays.hit, rays.sample,
//            rays.direction, gbuffer.albedo
//   outputs: rays.radiance (as fallback_probes: rgb the radiance, a -1 for an unresolved ray,
//            -2 for a resolved one); with "exit" occlusion_cells and occlusion_enclosure (R32F,
//            one texel per cell() x cell() pixels: the farthest layer-0 view depth of the cell,
//            and of it and its 8 neighbours; 1e30 where any pixel there shows the background)
// Runs after the tracer with fallback "environment" (the fallbacks "bvh" and "probes" own
// rays.radiance) and specular_occlusion other than "off". Counts the unresolved rays and the
// occluded ones (visibility below 1/2) for Frame.stats.
#pragma once

#include <algorithm>
#include <map>
#include <string>

#include "core/gl_resources.h"
#include "render/render_pass.h"

namespace ssr {

class SpecularOcclusionPass : public RenderPass {
public:
    std::string name() const override { return "specular_occlusion"; }
    // After a screen-space tracer whose unresolved rays take the environment.
    bool runs(const RenderSettings& s, const FrameFacts& f) const override {
        return f.reflections && s.method != TraceMethod::Bvh && enabled(s);
    }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override {
        return {"linear_depth", "gbuffer.normal", "gbuffer.material", "lit", "rays.hit", "rays.sample",
                "rays.direction", "gbuffer.albedo"};
    }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        std::vector<ResourceDesc> out = {
            {"rays.radiance", GL_RGBA32F, s.trace_width(), s.trace_height(), s.traced_rays(), 1}};
        if (s.specular_occlusion == SpecularOcclusion::Exit)
            for (const char* name : {"occlusion_cells", "occlusion_enclosure"})
                out.push_back({name, GL_R32F, (s.width + cell(s) - 1) / cell(s), (s.height + cell(s) - 1) / cell(s), 0, 1});
        return out;
    }
    // "exit": the side of an enclosure cell in pixels, 1/16 of the image height (as
    // shaders/passes/specular_occlusion.comp computes it).
    static int cell(const RenderSettings& s) { return std::max(4, s.height / 16); }
    void execute(FrameContext& ctx) override;

    // Whether the chain runs the pass for these settings.
    static bool enabled(const RenderSettings& s);
    // frame.stats: occluded_misses, unresolved_rays of the last run.
    std::map<std::string, double> counters() const;
    // The counters' storage buffer binding (shaders/passes/specular_occlusion.comp); its own, apart
    // from the covered tiles' (14), which the lighting and classify passes read.
    static constexpr GLuint kCountersBinding = kOcclusionCountersBinding;
    void report(const RenderSettings&, std::map<std::string, double>& stats) const override {
        for (const auto& [k, v] : counters()) stats[k] = v;
    }

private:
    Buffer counters_;
};

}  // namespace ssr
