// hiz_build: the min-max Hi-Z pyramid of every G-buffer layer (seed 002, 4.4.1, 4.5.1).
//   inputs : gbuffer.depth, gbuffer.material (coverage); linear_depth for the sight map
//   outputs: hiz (RG32F array of Settings.layers layers, full mip chain: level l holds, per
//            cell, the (min, max) screen depth of its covered level-0 pixels)
// One compute dispatch per level; odd-sized levels fold their last row/column into the
// last cell. Runs only for method="hiz".
//   hiz_trace (RG32F array, one level): the Hi-Z tracer's copy, every level in one image,
//            texels (min s, slab back s) (shaders/lib/hiz_atlas.glsl); written
//            only for method="hiz" (cone tracing reads "hiz"), and only the layers in use.
//            With sight(s) (the hybrid's confidence test, fallback "bvh"), also the sight map
//            below level 0, and the coarser levels' min is the sight map's: the nearest depth a
//            surface shown in or beside a pixel may reach inside it (shaders/lib/screen_sight.glsl).
#pragma once

#include <algorithm>

#include "render/render_pass.h"

namespace ssr {

class HizBuildPass : public RenderPass {
public:
    std::string name() const override { return "hiz_build"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override {
        // glossy="cone" needs the min-max pyramid whatever tracer follows the mirror ray.
        return f.reflections && (s.method == TraceMethod::Hiz || s.glossy == Glossy::Cone);
    }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override {
        if (sight(s)) return {"gbuffer.depth", "gbuffer.material", "linear_depth"};
        return {"gbuffer.depth", "gbuffer.material"};
    }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{"hiz", GL_RG32F, s.width, s.height, s.layers, 0, Lifetime::Scratch},
                {"hiz_trace", GL_RG32F, s.width + std::max(s.width >> 1, 1),
                 sight(s) ? std::max(s.height + levels_of(s), 2 * s.height) : s.height + levels_of(s), s.layers, 1,
                 Lifetime::Scratch}};
    }
    // Whether the Hi-Z walk ends where a ray leaves the G-buffer's sight (STOP_UNSEEN, as
    // trace_pass.cpp defines it) and so reads the sight map.
    static bool sight(const RenderSettings& s) {
        return s.method == TraceMethod::Hiz && s.fallback == Fallback::Bvh && s.fallback_confidence;
    }
    void execute(FrameContext& ctx) override;
    // Levels of the full mip chain of the image: floor(log2(max(width, height))) + 1.
    static int levels_of(const RenderSettings& s) {
        int n = 1;
        while ((std::max(s.width, s.height) >> n) > 0) ++n;
        return n;
    }
    // Layers the last run built (frame.stats["hiz_layers_built"]).
    int layers_built() const { return layers_built_; }
    void report(const RenderSettings&, std::map<std::string, double>& stats) const override {
        stats["hiz_layers_built"] = double(layers_built_);
    }

private:
    int layers_built_ = 0;
};

}  // namespace ssr
