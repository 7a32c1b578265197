// reproject: every pixel's position in the previous frame of a sequence and whether its
// history is valid (seed 002, 4.6.4, 4.6.5 and 4.7.4; shaders/passes/reproject.comp): the
// surface's motion vector (gbuffer.motion, which the deep G-buffer writes whenever this pass
// runs: writes_motion in render/render_pass.h), and the surface the previous frame shows there.
//   inputs : linear_depth, gbuffer.normal, gbuffer.material, gbuffer.motion (+ the previous
//            frame's depth, normal and material, every layer, from the sequence's history)
//   outputs: reprojection (RGBA32F: previous window position in pixels, valid, reason)
// In the chain whenever anything reprojects (reprojects() in render/render_pass.h): temporal
// reflections, clamped TAA, bounces through history, temporal ray reuse, or SVGF's temporal pass.
#pragma once

#include "render/render_pass.h"

namespace ssr {

// The camera's part of reprojection, formed in double precision so that a static camera
// reprojects to itself to float rounding (seed 002, Listing 4.9): identities without history.
struct HistoryCamera {
    glm::mat4 view_to_previous_clip{1.0f};  // VP_prev V^-1, VP_prev without the TAA jitter
    glm::mat4 previous_view_to_view{1.0f};  // V V_prev^-1
    glm::mat4 view_to_previous_view{1.0f};  // V_prev V^-1
    // Set on a program that declares them: u_view_to_previous_clip, u_previous_view_to_view,
    // u_view_to_previous_view.
    void set(GLuint program) const;
};

class ReprojectPass : public RenderPass {
public:
    // The frame's HistoryCamera (identities where ctx has no history uniforms).
    static HistoryCamera history_camera(const FrameContext& ctx);
    std::string name() const override { return "reproject"; }
    // Whenever a temporal technique that reprojects is on (render_pass.h).
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return reprojects(s, f); }
    std::vector<std::string> history_inputs(const RenderSettings&) const override {
        return {"linear_depth", "gbuffer.normal", "gbuffer.material"};
    }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override {
        return {"linear_depth", "gbuffer.normal", "gbuffer.material", "gbuffer.motion"};
    }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {texture("reprojection", s)};
    }
    void execute(FrameContext& ctx) override;
    // A reprojection texture (`name`: reprojection, or reprojection.reflection of the
    // reflection's reprojection) with what its channels mean (frame.reprojection).
    static ResourceDesc texture(const std::string& name, const RenderSettings& s);
};

}  // namespace ssr
