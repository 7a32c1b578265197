// The history of a sequence of frames (Renderer::render with a Sequence): the previous
// frame's textures and constants, which the temporal passes read (seed 002, 4.6.5 and 4.7.4;
// seed 000, 4.4). The renderer replaces them after every frame of the sequence; they are
// dropped with the Sequence, so nothing carries over from one sequence to the next.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/egl_context.h"
#include "render/gpu_structs.h"
#include "render/render_pass.h"
#include "render/settings.h"

namespace ssr {

class Sequence {
public:
    explicit Sequence(std::shared_ptr<EglContext> ctx) : ctx_(std::move(ctx)) {}
    ~Sequence() {
        // The textures die in their own context.
        try {
            CurrentContext current(*ctx_);
            previous.reset();
        } catch (...) {
        }
    }
    Sequence(const Sequence&) = delete;
    Sequence& operator=(const Sequence&) = delete;

    std::shared_ptr<FrameResources> previous;  // the previous frame's textures (null: no history)
    FrameUniforms previous_uniforms{};
    glm::mat4 previous_unjittered_proj{1.0f};  // its projection without the TAA jitter
    std::vector<glm::mat4> previous_models;    // its objects' model matrices (motion vectors)
    RenderSettings previous_settings;
    uint64_t scene_id = 0;
    uint64_t scene_revision = 0;  // the previous frame's Scene::geometry_revision
    int frames = 0;  // frames rendered so far in this sequence

    // The history usable by a frame of `s` showing `scene_id` at `geometry_revision`: same image
    // size, same scene and geometry. Objects that moved, materials and lights that changed keep
    // the history, as a camera that moved does: reprojection and the temporal passes' history
    // rejection are what deal with change (seed 002, 4.6.5); new geometry starts afresh.
    bool usable(const RenderSettings& s, uint64_t id, uint64_t geometry_revision) const {
        return previous && previous_settings.width == s.width && previous_settings.height == s.height &&
               scene_id == id && scene_revision == geometry_revision;
    }

private:
    std::shared_ptr<EglContext> ctx_;
};

}  // namespace ssr
