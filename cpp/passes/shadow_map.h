// shadow_map: depth from the directional light that casts the scene's shadow.
//   inputs : scene geometry
//   outputs: shadow_map (DEPTH32F, shadow_map_size^2)
// The light's orthographic frustum encloses the scene's bounding sphere. Runs only when a
// directional light casts a shadow and Settings.shadow_map_size > 0.
#pragma once

#include "render/render_pass.h"

namespace ssr {

struct ShadowSetup {
    bool enabled = false;
    int light = -1;                 // index into Scene::lights
    glm::mat4 light_view_proj{1};   // world -> light clip space (standard GL depth)
    float texel_world_size = 0.0f;  // world size of one shadow-map texel
};

class ShadowMapPass : public RenderPass {
public:
    std::string name() const override { return "shadow_map"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return f.shadows; }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override { return {}; }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override;
    void execute(FrameContext& ctx) override;

    // Which light casts the shadow and the light's frustum fitted to the scene.
    static ShadowSetup fit(const Scene& scene, const Bounds& bounds, const RenderSettings& s);
    void set_setup(const ShadowSetup& setup) { setup_ = setup; }
    void release() { fbo_.reset(); }

private:
    ShadowSetup setup_;
    Framebuffer fbo_;
};

}  // namespace ssr
