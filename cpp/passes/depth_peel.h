// depth_peel: the geometry pass, run once per layer (seed 000, 1.5.1 and 2.2).
//   inputs : scene geometry and materials
//   outputs: gbuffer.depth (DEPTH32F), gbuffer.albedo (SRGB8_ALPHA8: rgb base colour,
//            a metallic), gbuffer.normal (RGBA16F: view-space normal, roughness),
//            gbuffer.material (RGBA8: reflectivity, coverage), all 2D arrays of
//            Settings.layers layers; depth_peel.previous_depth (scratch); and, only where the
//            scene has an emissive texture (FrameFacts::emission_texture), gbuffer.emission
//            (RGBA16F: the surface's emitted radiance, glTF emissiveFactor x strength x texel);
//            only where it has a KHR_materials_specular texture (FrameFacts::specular_texture),
//            gbuffer.specular (RGBA16F: rgb every surface's dielectric F0, a 1 where covered)
// Layer 0 is the ordinary G-buffer. Layer i+1 re-renders the scene and discards every
// fragment that is not strictly behind layer i's depth at that pixel, so it holds the
// nearest surface behind layer i. Back-face culling is off by default, as in the thesis,
// so back faces populate deeper layers. Each layer is timed as depth_peel.layer<i>.
//
// Each layer is a depth pass (peel test only) and a shading pass at the kept depth
// (GL_EQUAL, early fragment tests), so the material runs once per covered pixel; the shading
// pass also marks the layer's covered 8x8 tiles in a buffer (the frame buffer "covered_tiles",
// shaders/lib/covered_tiles.glsl) that the lighting pass dispatches over; in layer 0 it also
// lists the 32x32 regions holding a reflective surface, which the classify pass dispatches
// over (a frame with no reflective pixel runs no classify group).
//
// Beyond the thesis: a layer that covers no pixel means every deeper layer is empty too, so
// each layer's draws are conditionally rendered on the previous layer's sample count
// (glBeginConditionalRender): the GPU skips the geometry of empty layers without a CPU
// round trip. Layers are still cleared, so they read back as empty.
//
// Settings.deep_gbuffer "lists" builds the same textures in one geometry pass (Yang et al. 2010's
// per-pixel linked lists; the thesis's 1.5 names the one-pass deep G-buffer as the way out of
// peeling's cost, seed 000 4.2): the shading pass's code appends every fragment's encoded outputs
// to its pixel's list (DEEP_GBUFFER_APPEND in depth_peel.frag), a compute pass keeps each pixel's
// `layers` nearest distinct depths by peeling's rules (deep_gbuffer_select.comp), and one
// full-screen draw per layer writes them through the same framebuffer formats
// (deep_gbuffer_write.frag): bit for bit the peeled layers. It is its own pass,
// fragment_lists (passes/fragment_lists.h), timed as fragment_lists.append, .select and .write
// (and, peeled beyond its budget, fragment_lists.layer<i>). The fragment store grows to the frame's fragment count within
// Settings.deep_gbuffer_budget; a frame beyond the budget is peeled (never truncated).
#pragma once

#include <functional>
#include <map>

#include "render/render_pass.h"

namespace ssr {

// Back faces culled as Settings.backface_culling says (counter-clockwise fronts, as glTF), for
// every construction of the deep G-buffer alike.
void apply_peel_culling(const RenderSettings& s);
// The state of a one-pass geometry pass that appends fragments to storage and writes no target
// (the shaded lists, the visibility lists): `fbo` (made on first use) without attachments, given
// the frame's size, bound; peeling's clip control and culling, no depth test, scissor or blend; the
// scene's geometry bound.
void begin_attachmentless_raster(FrameContext& ctx, Framebuffer& fbo);
// Settings.min_separation (Mara et al. 2016) for the peel test and the lists' selections alike
// (shaders/lib/layer_separation.glsl): 0 compiles the plain "strictly behind" test, so the
// default builds exactly the layers it built before the setting existed.
void set_min_separation(const RenderSettings& s, Defines& defines);
void set_min_separation(const RenderSettings& s, GLuint program);

// The bounding box, in 8x8 tiles, of the flagged tiles of one layer (`flags`: grid_x x grid_y,
// rows of tiles); x1 < 0 where none is flagged.
struct TileBounds {
    int x0, y0, x1, y1;
    bool empty() const { return x1 < 0; }
    bool whole(int grid_x, int grid_y) const { return x0 == 0 && y0 == 0 && x1 == grid_x - 1 && y1 == grid_y - 1; }
    // Scissors the raster to the box (a zero-sized scissor where it is empty).
    void scissor() const;
};
TileBounds tile_bounds(const GLuint* flags, int grid_x, int grid_y);

// The fragment store of a one-pass construction (the shaded lists, the visibility lists): sized by
// the previous frame (two fragments a pixel at first); where the counted fragments did not fit, the
// geometry pass runs again with a store of the count plus 1/8 (timed as `<prefix>.redo`), so a list
// is never truncated; beyond `max_fragments` nothing is kept and the caller peels instead.
// `append(capacity)` runs the geometry pass into a store of that capacity; the first word of
// `counter` is then the fragments it counted (also those beyond the capacity).
struct StoreGrowth {
    bool fits = false;       // the frame's fragments are in the store
    bool redone = false;     // ... after a second geometry pass
    uint64_t fragments = 0;  // counted
};
StoreGrowth grow_fragment_store(FrameContext& ctx, const std::string& prefix, uint64_t& capacity, uint64_t pixels,
                                uint64_t max_fragments, const Buffer& counter,
                                const std::function<void(uint64_t)>& append);

class DepthPeelPass : public RenderPass {
public:
    std::string name() const override { return "depth_peel"; }
    std::string part_of() const override { return "deep_gbuffer"; }
    // Peeling, and (passes/fragment_lists.h) the lists, which share its shading pass and its
    // textures, each under its own name.
    bool runs(const RenderSettings& s, const FrameFacts& f) const override {
        return !visibility_construction(s.deep_gbuffer) && s.deep_gbuffer != DeepGBuffer::Lists;
    }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override { return {}; }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override;
    // gbuffer.emission and gbuffer.specular: the lighting pass has no texture coordinates, so a
    // textured emission or specular F0 is sampled where the material is, in the shading pass, and
    // written as one more attachment each.
    std::vector<ResourceDesc> outputs(const RenderSettings& s, const FrameFacts& f) const override;
    std::vector<std::string> buffer_outputs(const RenderSettings&, const FrameFacts&) const override {
        return {"covered_tiles"};
    }
    void execute(FrameContext& ctx) override;

    // Pixels (samples passing the depth test) each layer of the last frame wrote (the lists:
    // the pixels each layer covers); read after the frame, when the GPU has finished.
    std::vector<uint64_t> layer_samples() override;
    void release() override;  // deletes the pass's GL objects (in the current context)

    // How the last run built the layers (Frame.stats): lists 1 = fragment lists, 0 = peeling;
    // fell_back 1 where "lists" was asked for and the frame's fragments exceeded the budget;
    // redone 1 where the store was too small and the geometry pass ran again with one that fits;
    // fragments: the frame's fragment count; bytes: the lists' buffers (store, heads, selection).
    struct ListStats {
        int lists = 0, fell_back = 0, redone = 0;
        uint64_t fragments = 0, bytes = 0;
    };
    const ListStats& list_stats() const { return list_stats_; }
    // A fragment-list budget the device cannot hold is refused before anything is allocated.
    void check_device(const RenderSettings& s) const override {
        if (s.deep_gbuffer == DeepGBuffer::Lists) store_limit_bytes(s.deep_gbuffer_budget);
    }
    // Where the lists were asked for: which method built the layers, and the lists' counts.
    void report(const RenderSettings& s, std::map<std::string, double>& stats) const override {
        if (s.deep_gbuffer != DeepGBuffer::Lists) return;
        stats["deep_gbuffer_lists"] = double(list_stats_.lists);
        stats["deep_gbuffer_fell_back"] = double(list_stats_.fell_back);
        stats["deep_gbuffer_redone"] = double(list_stats_.redone);
        stats["deep_gbuffer_fragments"] = double(list_stats_.fragments);
        stats["deep_gbuffer_bytes"] = double(list_stats_.bytes);
    }
    static constexpr size_t kFragmentBytes = 64;  // struct ListFragment, lib/fragment_lists.glsl
    static constexpr size_t kExtraOutputBytes = 16;  // ... and a vec4 more for each of gbuffer.emission, .specular, .motion
    // The fragment store's largest size for Settings.deep_gbuffer_budget (0: the device's largest
    // storage buffer); std::invalid_argument where the budget is beyond what the device can hold.
    static uint64_t store_limit_bytes(int budget_mib);

    // The covered-tile buffer ("covered_tiles", shaders/lib/covered_tiles.glsl), bound as SSBO
    // kCoveredTilesBinding: flags and a list of tiles per layer, then layer 0's regions.
    static constexpr GLuint kCoveredTilesBinding = ssr::kCoveredTilesBinding;
    // Sizes the covered-tile buffer `tiles` for the frame, clears its flags and lists, binds it as
    // kCoveredTilesBinding and publishes it as "covered_tiles" (every construction of the deep
    // G-buffer marks the same tiles in it).
    static void prepare_covered_tiles(FrameContext& ctx, Buffer& tiles);
    static int covered_tiles_per_layer(const RenderSettings& s) { return ((s.width + 7) / 8) * ((s.height + 7) / 8); }
    // Layer 0's reflective 32x32 regions, listed for the classify pass's indirect
    // dispatch: their count and the byte offset of the dispatch arguments in the buffer.
    static int classify_regions(const RenderSettings& s) { return ((s.width + 31) / 32) * ((s.height + 31) / 32); }
    static size_t classify_regions_offset(const RenderSettings& s) {
        return sizeof(GLuint) * (4 + 2 * size_t(covered_tiles_per_layer(s)) * size_t(s.layers));
    }

protected:
    // The shading pass's program for each material kind of the scene (GpuScene::material_features),
    // compiled from `base` (the pass's defines).
    std::map<int, GLuint> shading_programs(FrameContext& ctx, const Defines& base) const;
    void prepare_tiles(FrameContext& ctx);
    void peel(FrameContext& ctx);
    // false: the fragments exceed the budget (nothing written; the caller peels).
    bool lists(FrameContext& ctx);
    void append(FrameContext& ctx, uint64_t capacity);
    // The G-buffer's colour outputs this frame: 3, and gbuffer.emission, then gbuffer.specular,
    // where the facts say so (their attachment and fragment-shader location is their index).
    bool has_emission() const { return defines_.count("EMISSION_TEXTURE") != 0; }
    bool has_specular() const { return defines_.count("SPECULAR_TEXTURE") != 0; }
    bool has_motion() const { return defines_.count("MOTION_VECTORS") != 0; }
    int colour_outputs() const { return 3 + int(has_emission()) + int(has_specular()) + int(has_motion()); }
    GLenum specular_attachment() const { return GLenum(GL_COLOR_ATTACHMENT3 + int(has_emission())); }
    GLenum motion_attachment() const {
        return GLenum(GL_COLOR_ATTACHMENT3 + int(has_emission()) + int(has_specular()));
    }
    // Attaches layer `layer` of every colour output the frame has to fbo_.
    void attach_outputs(FrameContext& ctx, int layer);
    void detach_optional_outputs();
    size_t fragment_bytes() const { return kFragmentBytes + kExtraOutputBytes * size_t(colour_outputs() - 3); }

    // the frame's common defines, and EMISSION_TEXTURE / SPECULAR_TEXTURE where the facts say so,
    // MOTION_VECTORS where the settings do
    Defines defines_;

    Framebuffer fbo_, empty_fbo_;
    std::vector<GLuint> queries_;
    int used_queries_ = 0;
    Buffer tiles_;
    // Fragment lists: the store, counter (appended, capacity, most layers), heads, kept slots.
    Buffer store_, counter_, heads_, kept_;
    uint64_t capacity_ = 0;  // fragments the store holds
    GLuint empty_vao_ = 0;
    ListStats list_stats_;
    std::vector<uint64_t> list_samples_;  // pixels each layer covers, from the lists' selection
};

}  // namespace ssr
