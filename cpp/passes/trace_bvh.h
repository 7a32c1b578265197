// trace_bvh: reflection rays traced against the scene's triangles and shaded by the G-buffer's
// own shading code (shaders/passes/trace_bvh.comp, shaders/lib/trace_shade.glsl).
// Two uses:
//   method "bvh" (seed 003's ray-traced reflections): every ray, no screen space.
//     inputs : linear_depth, gbuffer.albedo, gbuffer.normal, gbuffer.material (+ shadow_map)
//     outputs: rays.hit, rays.sample, rays.direction (see trace_pass.h), rays.radiance
//     With Settings.skip the rays with a weight are compacted into the fallback's
//     list first and traced by indirect dispatch over it; adaptive_rays as the other tracers.
//   fallback "bvh" (thesis 4.3, seed 004): after a screen-space tracer, only the rays it could
//     not resolve (a miss, a faded hit, a hit failing the confidence test) are retraced: a
//     full-screen selection appends them to a compacted list (atomic counter), whose count
//     sizes an indirect dispatch over the list only.
//     inputs : the above + rays.hit, rays.sample, rays.direction
//     outputs: rays.radiance; with fallback_confidence, rays.hit rewritten: a screen-space hit
//              failing the confidence test becomes a miss marked (0, 0, 0, -1) (as the tracer
//              marks a ray it handed over when it left the G-buffer's sight), a kept one moves to
//              the pixel where the ray crosses its face (shaders/lib/screen_confidence.glsl)
// rays.radiance (RGBA32F, trace resolution, one layer per ray): rgb the ray's BVH radiance,
// a its hit distance (-1: the BVH found nothing, the environment's radiance; -2: not traced).
#pragma once

#include "core/gl_resources.h"
#include "passes/trace_pass.h"

namespace ssr {

class TraceBvhPass : public TracePass {
public:
    // With or without the shadow map (FrameFacts.shadows): defines of one program.
    explicit TraceBvhPass(bool fallback) : fallback_(fallback) {}
    std::string name() const override { return fallback_ ? "fallback_bvh" : "trace_bvh"; }
    std::string stage() const override { return "bvh"; }  // not the screen-space trace a user pass replaces
    bool runs(const RenderSettings& s, const FrameFacts& f) const override {
        // Seed 003's ray-traced reflections (every ray), or the hybrid's fallback after a
        // screen-space tracer (thesis 4.3).
        if (!f.reflections) return false;
        return fallback_ ? s.method != TraceMethod::Bvh && s.fallback == Fallback::Bvh : s.method == TraceMethod::Bvh;
    }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override;
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override;
    // The fallback writes the hits it finds into the screen-space trace's rays.hit.
    std::vector<std::string> rewrites(const RenderSettings& s, const FrameFacts&) const override {
        if (fallback_) return {"rays.hit"};
        return {};
    }
    // It compacts its own list of rays (below), not classify's.
    std::vector<std::string> buffer_inputs(const RenderSettings&, const FrameFacts&) const override { return {}; }
    void execute(FrameContext& ctx) override;

private:
    bool fallback_;
    Buffer list_, count_;  // the compacted list of rays to (re)trace, its count + indirect args
};

}  // namespace ssr
