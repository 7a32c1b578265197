// classify (seed 000 4.1, seed 003's roughness threshold, seed 004's early out by
// roughness and angle; FidelityFX SSSR's classification): marks the trace pixels that need
// rays and compacts them into a ray list with an atomic counter, in a buffer that also holds
// the trace pass's indirect dispatch arguments: the trace pass then runs over the list only,
// and an empty list costs it no work. It runs by indirect dispatch over the 32x32 regions where
// the peeling drew a reflective surface in layer 0 (covered_tiles.glsl). The pixels left out
// read as the trace pass's "no ray", all zeros: rays.sample is cleared, timed with this pass
// (rays.hit and rays.direction are read only where its traced flag is set). When the resolve
// follows (resolves_over_lists), it also lists the resolve's work, the receiving pixels (own
// rays) or the 16x16 tiles holding one, and writes the environment of the reflective pixels
// rougher than the cutoff into a cleared reflection texture (shaders/passes/classify.comp).
//   inputs : linear_depth, gbuffer.albedo, gbuffer.normal, gbuffer.material; the buffer
//            covered_tiles (the peeling's)
//   outputs: rays.* (rays.sample cleared, the rays adaptive_rays leaves out; the trace that
//            follows rewrites them), the reflection of the non-receivers when the resolve runs
//            over lists (the resolve rewrites it); the buffers ray_list and, when the resolve
//            runs over lists, resolve_list (FrameBuffer)
#pragma once

#include <map>

#include "passes/depth_peel.h"
#include "render/render_pass.h"

namespace ssr {

class ClassifyPass : public RenderPass {
public:
    std::string name() const override { return "classify"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override {
        // The screen-space traces run over its ray list (indirect dispatch).
        return f.reflections && s.method != TraceMethod::Bvh && s.skip;
    }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override {
        return {"linear_depth", "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"};
    }
    // The ray textures (the trace that follows rewrites them), and where the resolve runs over
    // its lists the reflection of the non-receivers (the resolve rewrites it).
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override;
    // Whether this pass writes the ray textures before the screen-space trace (it runs then).
    static bool writes_rays(const RenderSettings& s) {
        return s.skip && s.method != TraceMethod::Bvh && s.method != TraceMethod::Off;
    }
    // The peeling's list of the 32x32 regions where layer 0 holds a reflective surface: the
    // blocks of the other regions are skipped without a fetch.
    std::vector<std::string> buffer_inputs(const RenderSettings&, const FrameFacts&) const override {
        return {"covered_tiles"};
    }
    std::vector<std::string> buffer_outputs(const RenderSettings& s, const FrameFacts&) const override {
        if (resolves_over_lists(s)) return {"ray_list", "resolve_list"};
        return {"ray_list"};
    }
    void execute(FrameContext& ctx) override;

    // The SSBO binding of the ray list (shaders/lib/ray_list.glsl).
    static constexpr GLuint kBinding = kRayListBinding;
    // The list's counters of the last run, read back from the GPU (Frame.stats).
    std::map<std::string, double> counters() const;
    void report(const RenderSettings&, std::map<std::string, double>& stats) const override {
        for (const auto& [k, v] : counters()) stats[k] = v;
    }
    // Whether the list holds one entry per (pixel, ray): Settings.adaptive_rays with skip.
    static bool per_ray(const RenderSettings& s) { return s.skip && s.adaptive_rays && s.traced_rays() > 1; }
    // Whether the resolve runs over this pass's resolve list (Settings.skip, the stochastic
    // resolve after a screen-space trace).
    static bool resolves_over_lists(const RenderSettings& s) {
        return s.skip && s.method != TraceMethod::Bvh && s.method != TraceMethod::Off && s.glossy == Glossy::Stochastic;
    }
    // The SSBO binding of the resolve list (shaders/lib/resolve_list.glsl).
    static constexpr GLuint kResolveBinding = kResolveListBinding;

protected:
    // Also the variance_rays pass's list of pixels that get extra rays (same layout).
    Buffer list_;
    // The trace's indirect arguments: a copy of the list header's first three words (see bind()).
    mutable Buffer dispatch_args_;
    // A list of `w` x `h` entries at most with a fresh header: no group, `rays` group layers.
    // `per_ray`: entries of (pixel, ray) for `rays` rays per pixel at most, dispatched with one
    // group layer (adaptive rays over the list, ray_list.glsl's RAY_LIST_PER_RAY).
    void reset_list(int w, int h, int rays, bool per_ray = false);
    bool per_ray_ = false;  // the last run listed (pixel, ray) entries
    // Binds the list as SSBO kBinding, for this pass's shader to fill.
    void bind_list() const;
    // Publishes the filled list as the frame buffer `name`, with a copy of its dispatch
    // arguments as the indirect buffer (see classify.cpp).
    void publish_list(FrameContext& ctx, const std::string& name) const;

private:
    const Buffer* regions_ = nullptr;  // the last run's region list (the peel's buffer), or none
    size_t regions_offset_ = 0;
    Buffer resolve_list_;
    bool resolve_lists_ = false;     // the last run wrote the resolve list
    bool resolve_pixels_ = false;    // ... of pixels (the own-rays resolve), else of tiles
    void reset_resolve_list(int width, int height, bool pixels);
};

}  // namespace ssr
