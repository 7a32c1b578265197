// shadow_map: depth from every light that casts a shadow (Light::cast_shadow).
//   inputs : scene geometry
//   outputs: shadow_map   (DEPTH32F 2D array, shadow_map_size^2, one layer per directional or
//                          spot caster; FrameFacts.shadow_maps layers)
//            shadow_cubes (DEPTH32F cube-map array, shadow_map_size^2 faces, one cube per point
//                          caster; FrameFacts.shadow_cubes cubes)
// A directional light's layer is an orthographic frustum enclosing the scene's bounding sphere,
// a spot light's a perspective frustum over its outer cone, a point light's cube six 90-degree
// perspective faces. Runs only when some light casts a shadow and Settings.shadow_map_size > 0.
// Readers (lighting, the BVH passes, the probes' capture, the GLSL reference) read every map
// through lib/shadow_map.glsl; each light finds its own in the lights buffer (GpuLight::shadow).
// The maps are per-renderer scratch that outlives the frame: each layer and cube remembers what
// it holds (a key of its frustum and the map size, and GpuScene::caster_state: every object's
// transform and geometry and the alpha-tested materials' tests). Frames of a sequence, sweeps
// over reflection settings and repeated renders reuse it (frame.stats["shadow_maps_reused"], the
// pass's timing 0 when every map was reused); a moved object redraws only the texels its old
// and new bounds reach ("shadow_maps_updated"); a new frustum, new geometry or a replaced
// texture draws the map again ("shadow_maps_rendered").
#pragma once

#include "render/render_pass.h"

namespace ssr {

// One shadow-casting light and its map.
struct ShadowCaster {
    int light = -1;                 // index into Scene::lights
    bool cube = false;              // a point light: a cube of shadow_cubes; else a layer of shadow_map
    int slot = 0;                   // its layer of shadow_map or its cube of shadow_cubes
    glm::mat4 light_view_proj{1};   // a layer: world -> light clip space (standard GL depth)
    glm::vec3 position{0.0f};       // a cube: the light's world position
    float near_plane = 0.0f, far_plane = 0.0f;  // a cube: its faces' depth range
    float texel_world_size = 0.0f;  // a layer: world size of one texel (a spot's at the scene's centre)
};

struct ShadowSetup {
    bool enabled = false;             // some light casts a shadow
    std::vector<ShadowCaster> casters;  // in Scene::lights order
    int maps = 0, cubes = 0;          // layers of shadow_map, cubes of shadow_cubes
    // The first layer's caster (Frame.shadow_matrix, FrameUniforms::view_to_shadow): -1 if none.
    int light = -1;
    glm::mat4 light_view_proj{1};
    float texel_world_size = 0.0f;
    // The caster of Scene::lights[i], or null.
    const ShadowCaster* caster_of(int i) const {
        for (const auto& c : casters)
            if (c.light == i) return &c;
        return nullptr;
    }
};

class ShadowMapPass : public RenderPass {
public:
    std::string name() const override { return "shadow_map"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return f.shadows; }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override { return {}; }
    // Every texture it may write (one layer and one cube): for listings without a frame's facts.
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override;
    // The frame's: a layer per directional or spot caster, a cube per point caster.
    std::vector<ResourceDesc> outputs(const RenderSettings& s, const FrameFacts& f) const override;
    void execute(FrameContext& ctx) override;
    void begin_frame() override;
    bool reused() const override { return rendered_ == 0 && updated_ == 0 && reused_ > 0; }
    // shadow_maps_reused, shadow_maps_updated, shadow_maps_rendered: layers and cubes of the timed run.
    void report(const RenderSettings& s, std::map<std::string, double>& stats) const override;

    // Which lights cast shadows and their frusta fitted to the scene.
    static ShadowSetup fit(const Scene& scene, const Bounds& bounds, const RenderSettings& s);
    void set_setup(const ShadowSetup& setup) { setup_ = setup; }
    void release() override {
        fbo_.reset();
        maps_ = Held{};
        cubes_ = Held{};
    }

    // For the passes that read the maps (lib/shadow_map.glsl): the textures they read, bound by
    // name with the pass's other textures (TEXTURE_SHADOW_MAP, TEXTURE_SHADOW_CUBES), and the
    // defines saying which kinds the frame has (SHADOW_MAPS, SHADOW_CUBES, with SHADOWS 1).
    static std::vector<std::string> reads(const FrameFacts& f);
    static void add_defines(Defines& d, const FrameFacts& f);

private:
    void draw_scene(FrameContext& ctx, const glm::mat4& light_view_proj, GLuint prog, GLint loc_vp, GLint loc_object,
                    GLuint alpha_prog, GLint loc_alpha_vp, GLint loc_alpha_object,
                    const std::vector<uint8_t>* only = nullptr);
    // What a layer of shadow_map (or a cube of shadow_cubes) holds: the key of its frustum and
    // size (frustum_key; 0: nothing known) and the GpuScene::caster_state it was drawn at.
    struct Slot {
        uint64_t frustum = 0, state = 0;
    };
    // The slots of one texture allocation (FrameResources::generation).
    struct Held {
        uint64_t generation = 0;
        std::vector<Slot> slots;
    };
    static uint64_t frustum_key(const ShadowCaster& c, int size);
    ShadowSetup setup_;
    Framebuffer fbo_;
    Held maps_, cubes_;
    Held maps_at_start_, cubes_at_start_;        // as the frame began (begin_frame)
    int reused_ = 0, updated_ = 0, rendered_ = 0;  // the last run's layers and cubes
};

}  // namespace ssr
