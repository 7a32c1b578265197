// resolve: ray results -> reflection colour per pixel, with neighbour ray reuse and
// edge-aware upsampling of downscaled rays (seed 000, 2.4 and 2.6; shaders/passes/resolve.comp).
//   inputs : rays.hit, rays.sample, rays.direction, lit, linear_depth, gbuffer.albedo,
//            gbuffer.normal, gbuffer.material
//            (+ rays.radiance with method or fallback "bvh")
//   outputs: reflection (RGBA16F, full resolution; 0 where a pixel does not reflect)
// With Settings.skip it runs by indirect dispatch over the classify pass's buffer resolve_list
// only: the receiving pixels (own rays) or the 16x16 tiles holding one; the classify pass
// wrote the other pixels' reflection.
#pragma once

#include "passes/compute.h"
#include "render/render_pass.h"

namespace ssr {

class ResolvePass : public RenderPass {
public:
    // Where no neighbour's ray can weigh anything (full-resolution rays with reuse
    // radius 0, or mirror rays with BRDF weights, which serve only their own pixel), each pixel
    // reads its own rays directly: no shared tile and no barriers, the same sums.
    static bool own_rays_only(const RenderSettings& s) {
        return s.downscale == 1 &&
               (s.reuse_radius == 0 || (s.sampling == Sampling::Mirror && s.reuse_weighting == ReuseWeighting::Brdf));
    }
    // Whether the neighbours' rays come from the shared tile the resolve fills itself (the
    // thesis's design, GPUs) or, where the passes read by imageLoad (llvmpipe, whose shared-memory
    // loads are slow), from resolve_fetch's textures, which then runs before it in the chain.
    static bool shared_tile(const RenderSettings& s, bool fetch_by_image);
    // What lib/resolve_ray.glsl is compiled with and binds, for the resolve and resolve_fetch alike:
    // rays traced by the BVH (method or fallback "bvh") or the probes bring their radiance
    // in rays.radiance; the inputs by name (ray_units), with FETCH_BY_IMAGE the float ones as images.
    static bool ray_radiance(const RenderSettings& s);
    static Defines ray_defines(const FrameContext& ctx);
    // What lib/resolve_ray.glsl reads, by name (the float inputs by imageLoad on the CPU device;
    // "previous.color": the previous frame's colour for bounces "history", or a stand-in);
    // a pass adds its own and binds them with bind_ray_inputs, which also sets u_has_history.
    static NamedUnits ray_units(const FrameContext& ctx);
    static void bind_ray_inputs(FrameContext& ctx, GLuint prog, const NamedUnits& units, const std::string& shader);
    // What bind_ray_inputs binds with these settings (the resolve's and resolve_fetch's inputs).
    static std::vector<std::string> ray_inputs(const RenderSettings& s);
    std::string name() const override { return "resolve"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return f.reflections && s.glossy == Glossy::Stochastic; }
    std::vector<std::string> history_inputs(const RenderSettings& s) const override {
        return s.bounces == Bounces::History ? std::vector<std::string>{"color"} : std::vector<std::string>{};
    }
    // The rays and the G-buffer; the rays' radiance where a pass writes it (ray_radiance),
    // resolve_fetch's textures where it runs, the reprojection where the rays or the bounces come
    // from the previous frame.
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override;
    // The reflection is classify's where the resolve runs over its lists (it wrote the
    // non-receivers'); this pass rewrites it then.
    std::vector<std::string> rewrites(const RenderSettings& s, const FrameFacts&) const override;
    static ResourceDesc reflection_texture(const RenderSettings& s) {
        return {"reflection", GL_RGBA16F, s.width, s.height, 0, 1};
    }
    // The stage a user pass of stage "reflection_filter" follows (passes/user_pass.h).
    std::string stage() const override { return "resolve"; }
    // With Settings.skip and the stochastic resolve: classify's list of the receivers.
    std::vector<std::string> buffer_inputs(const RenderSettings& s, const FrameFacts& f) const override;
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override;
    void execute(FrameContext& ctx) override;

private:
};

}  // namespace ssr
