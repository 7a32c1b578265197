// reference: ground-truth reflections traced against the scene's triangles on the GPU
// (shaders/passes/reference.comp; BVH from cpp/scene/bvh.cpp). Not part of a frame's chain:
// Renderer::reference runs it on a frame that has been rendered, reading that frame's
// G-buffer, shadow map and rays.
//   per-ray mode   inputs : linear_depth, gbuffer.*, rays.direction, rays.sample (+ shadow_map)
//                  outputs: reference.hit (x, y pixels, object + 1, t), reference.position
//                           (view-space hit, on-screen flag), reference.radiance (rgb, weight),
//                           at the trace resolution, one layer per ray
//   converged mode inputs : linear_depth, gbuffer.* (+ shadow_map)
//                  outputs: reference.accum (sum w c, sum w), reference.reflection, full resolution
#pragma once

#include "render/render_pass.h"

namespace ssr {

class ReferencePass : public RenderPass {
public:
    ReferencePass(bool per_ray, bool shadows, int rays, bool viewer_is_ray)
        : per_ray_(per_ray), shadows_(shadows), viewer_is_ray_(viewer_is_ray), rays_(rays) {}
    std::string name() const override { return "reference"; }
    std::vector<std::string> inputs() const override;
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override;
    void execute(FrameContext& ctx) override;

private:
    bool per_ray_, shadows_, viewer_is_ray_;
    int rays_;
};

}  // namespace ssr
