// resolve_fetch: the resolve's tile fill into textures, where shared memory is slow
// (shaders/passes/resolve_fetch.comp): every (trace pixel, ray) slot's radiance and weight, and its
// hit point or direction with its pdf, for the resolve to read its neighbours' rays by imageLoad.
// In the chain before the resolve when the passes read by imageLoad (Renderer input_fetch, the CPU
// device by default) and the resolve reuses neighbours' rays (not ResolvePass::own_rays_only).
//   inputs : rays.hit, rays.sample, rays.direction, lit, linear_depth, gbuffer.albedo,
//            gbuffer.normal, gbuffer.material (+ rays.radiance, as the resolve)
//   outputs: resolve.ray_color, resolve.ray_target (RGBA32F, trace resolution, one layer per ray)
#pragma once

#include "passes/resolve.h"
#include "render/render_pass.h"

namespace ssr {

class ResolveFetchPass : public RenderPass {
public:
    std::string name() const override { return "resolve_fetch"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override {
        // Where the passes read by imageLoad (llvmpipe), the neighbours' rays reach the resolve
        // through this pass's textures instead of its shared tile.
        return f.reflections && s.glossy == Glossy::Stochastic && !ResolvePass::own_rays_only(s) &&
               !ResolvePass::shared_tile(s, f.fetch_by_image);
    }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override {
        return ResolvePass::ray_inputs(s);
    }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        const int w = s.trace_width(), h = s.trace_height(), r = s.traced_rays();
        return {{"resolve.ray_color", GL_RGBA32F, w, h, r, 1}, {"resolve.ray_target", GL_RGBA32F, w, h, r, 1}};
    }
    void execute(FrameContext& ctx) override;
};

}  // namespace ssr
