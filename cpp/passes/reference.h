// reference: ground-truth reflections traced against the scene's triangles on the GPU
// (shaders/passes/reference.comp; BVH from cpp/scene/bvh.cpp). Not part of a frame's chain:
// Renderer::reference runs it on a frame that has been rendered, reading that frame's
// G-buffer, shadow map and rays.
//   per-ray mode   inputs : linear_depth, gbuffer.*, rays.direction, rays.sample (+ shadow_map)
//                  outputs: reference.hit (x, y pixels, object + 1, t), reference.position
//                           (view-space hit, on-screen flag), reference.radiance (rgb, weight),
//                           at the trace resolution, one layer per ray
//   converged mode inputs : linear_depth, gbuffer.* (+ shadow_map)
//                  outputs: reference.accum (sum w c, sum w), reference.reflection, reference.direct
//                           (the pixel's own direct light at its exact point), full resolution
// Shadows come from the frame's shadow map, or from shadow rays traced against the triangles
// (traced_shadows: exact, the reference's default).
#pragma once

#include "render/render_pass.h"

namespace ssr {

class ReferencePass : public RenderPass {
public:
    // shadows: the frame has a shadowed light; traced_shadows: trace its shadows instead of
    // reading the frame's shadow map.
    ReferencePass(bool per_ray, bool shadows, bool traced_shadows, int rays, bool viewer_is_ray)
        : per_ray_(per_ray), shadows_(shadows), traced_shadows_(traced_shadows), viewer_is_ray_(viewer_is_ray),
          rays_(rays) {}
    std::string name() const override { return "reference"; }
    // On request only (Renderer::reference), never in a frame's chain.
    bool runs(const RenderSettings&, const FrameFacts&) const override { return false; }
    std::vector<std::string> inputs() const override;
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override;
    void execute(FrameContext& ctx) override;
    // Compiles the program before the timed execution.
    GLuint program(FrameContext& ctx) const;

private:
    bool per_ray_, shadows_, traced_shadows_, viewer_is_ray_;
    int rays_;
};

}  // namespace ssr
