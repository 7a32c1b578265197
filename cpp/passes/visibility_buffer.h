// visibility_buffer: the geometry pass of the visibility constructions of the deep G-buffer
// (Settings.deep_gbuffer "visibility" and "visibility_lists"): Burns and Hunt 2013's visibility
// buffer applied to every layer (seed 000, 2.2). The raster writes what visibility needs only, a
// depth and the fragment's triangle, through the depth test and one 32-bit target, and a compute
// pass rebuilds every attribute of the kept samples afterwards (passes/gbuffer_attributes.h). On
// GPUs with few raster output units (NVIDIA's H100 and H200), framebuffer clears and colour outputs
// of the G-buffer's four formats were the slow path of the frame: 0.70 ms of clears and a 1.35 ms
// draw per 1080p layer, where depth and a triangle id cost 0.64 and the attributes by compute
// stores 0.03 (../shared/GPU.md).
//   inputs : scene geometry and materials (alpha-tested ones: their base colour texture)
//   outputs: gbuffer.depth (the layers' window depths, as peeling writes them: a DEPTH32F array,
//            where lists are built (builds_lists) an R32F array stored by compute),
//            gbuffer.visibility (R32UI array, scratch: each sample's id, its object and triangle,
//            lib/visibility.glsl; meaningful where the depth is not the clear value),
//            visibility_buffer.previous_depth (scratch), where lists are built
//            visibility_buffer.raster_depth (scratch: the depth target of a frame it peels)
// "visibility": peeling (Everitt 2001): layer i+1 keeps the nearest fragment strictly behind layer
// i (Settings.min_separation: that far behind), with peeling's culling, alpha test and ties: the
// draws go in reverse order with a depth test that passes equal depths, so of fragments at one
// depth the first draw's, and within a draw the last triangle's, stays: the one peeling's shading
// pass leaves. Layers after an empty one are skipped by conditional rendering. Timed as
// visibility_buffer.layer<i>.
// "visibility_lists": one geometry pass appends every fragment's depth and triangle to its pixel's
// list (12 bytes a fragment, lib/visibility_lists.glsl), a compute pass keeps the `layers`
// nearest by peeling's rules and stores their ids and depths (passes/visibility_select.comp): no
// raster output after the append. The geometry is processed once whatever the layer count. The
// store grows to the frame's fragment count within Settings.deep_gbuffer_budget; a frame beyond it
// is peeled, each layer's depth rasterised into a depth target and stored into gbuffer.depth by
// compute (passes/visibility_depth.comp). Timed as visibility_buffer.append, .select. One layer
// builds no list: the nearest fragment of each pixel is what the depth test keeps, so that layer is
// rasterised as "visibility" rasterises it, in one pass too, without storing every fragment
// (Frame.stats["deep_gbuffer_method"] 'visibility').
#pragma once

#include <map>

#include "render/render_pass.h"

namespace ssr {

class VisibilityBufferPass : public RenderPass {
public:
    std::string name() const override { return "visibility_buffer"; }
    std::string part_of() const override { return "deep_gbuffer"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override {
        return visibility_construction(s.deep_gbuffer);
    }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override { return {}; }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override;
    // On the CPU device the covered 8x8 tiles of every layer (lib/visibility_tiles.glsl), marked
    // as the layers are built; elsewhere not marked (the attribute pass then covers every tile).
    // "visibility_samples": with "visibility_lists" on the CPU device, more than one layer and no
    // textured material, every kept sample listed by the selection with each layer's count
    // (lib/visibility_samples.glsl; its `args` the counts, the shade stage's indirect dispatch
    // first); elsewhere published empty (no data).
    std::vector<std::string> buffer_outputs(const RenderSettings&, const FrameFacts&) const override {
        return {"visibility_tiles", "visibility_samples"};
    }
    void check_device(const RenderSettings& s) const override;
    // Whether the frame builds the per-pixel lists: "visibility_lists" with more than one layer.
    static bool builds_lists(const RenderSettings& s) {
        return s.deep_gbuffer == DeepGBuffer::VisibilityLists && s.layers > 1;
    }
    void execute(FrameContext& ctx) override;
    void report(const RenderSettings& s, std::map<std::string, double>& stats) const override;
    void release() override;

    static constexpr size_t kFragmentBytes = 12;  // lib/visibility_lists.glsl: depth, id, link
    static constexpr GLuint kTilesBinding = kVisibilityTilesBinding;   // lib/visibility_tiles.glsl
    // Whether the tiles are marked (Renderer.visibility_tiles: on the CPU device by default, where
    // llvmpipe rasterises and shades whatever it is given; a GPU is not stalled to read them back).
    static bool marks_tiles(const FrameContext& ctx) { return ctx.visibility_tiles; }
    // The low bits of a sample id that hold the triangle (lib/visibility.glsl): as many as the
    // scene's largest draw needs; the draw takes the rest. A scene whose draws and triangles do not
    // fit 32 bits together is refused (std::invalid_argument naming the setting).
    static int primitive_bits(const GpuScene& scene, DeepGBuffer construction);

private:
    void peel(FrameContext& ctx);
    // false: the fragments exceed the budget (nothing written; the caller peels).
    bool lists(FrameContext& ctx);
    void append(FrameContext& ctx, uint64_t capacity);
    // Draws every object (reverse order: peeling's tie rule, see above) with the program for its
    // material (the alpha-tested variant where it makes holes).
    void draw_scene(FrameContext& ctx, GLuint prog, GLuint alpha_prog) const;

    int primitive_bits_ = 0;
    Buffer tiles_;
    Framebuffer fbo_, empty_fbo_;
    std::vector<GLuint> queries_;
    // Lists: fragments (depth, triangle), links, heads, counter (appended, capacity, most layers).
    Buffer fragments_, links_, heads_, counter_;
    // The samples the selection lists for the attribute pass, and their counts
    // (lib/visibility_samples.glsl).
    Buffer samples_, sample_counts_;
    uint64_t capacity_ = 0;
    struct ListStats {
        int lists = 0, fell_back = 0, redone = 0, samples_listed = 0;
        uint64_t fragments = 0, bytes = 0;
    } list_stats_;
};

}  // namespace ssr
