// gbuffer_attributes: the visibility constructions' attribute pass (Settings.deep_gbuffer
// "visibility" and "visibility_lists"): every attribute of every sample the visibility buffer
// kept (passes/visibility_buffer.h), rebuilt from its triangle and the pixel's primary ray and
// shaded by peeling's own material code, then written by image stores (Burns and Hunt 2013;
// shaders/passes/gbuffer_attributes.comp says how). No colour target is cleared or drawn: every
// texel of the filled layers is stored once, the empty layers are cleared.
//   inputs : gbuffer.depth, gbuffer.visibility; the buffers "visibility_tiles" (the CPU device)
//            and "visibility_samples" (the samples and their counts, where the selection of
//            "visibility_lists" listed them: shaded from that list, no texel classified)
//   outputs: gbuffer.albedo, gbuffer.normal, gbuffer.material (and gbuffer.emission,
//            gbuffer.specular where the frame's facts say so): the names, formats and layers
//            depth peeling writes (passes/depth_peel.h); the buffer "covered_tiles", marked as
//            peeling marks it
// Samples of untextured materials are shaded in one dispatch; those of a material with textures
// are binned by material (a count, a prefix sum and a scatter on the GPU) and shaded by one
// indirect dispatch per such material with its textures bound, mipmapped as the raster samples
// them, the level chosen from the differences over the pixel's 2x2 quad (ray differentials one
// pixel apart) that a fragment shader's derivatives take. On the CPU device every sample is binned
// or listed (llvmpipe shades both sides of a branch for every lane). What the samples of one
// triangle share (its view-space vertices and normals) is computed first, once per triangle of the
// scene, into a record of 80 bytes, where the frame has at least 4 texels a triangle. Layer 0's
// reflective samples flag their 32x32 region (no atomic per sample), and a last dispatch lists
// the flagged regions for the classify pass. Timed as gbuffer_attributes.triangles, .classify,
// .bin, .shade and .regions.
#pragma once

#include <map>

#include "render/render_pass.h"

namespace ssr {

class GBufferAttributesPass : public RenderPass {
public:
    std::string name() const override { return "gbuffer_attributes"; }
    std::string part_of() const override { return "deep_gbuffer"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override {
        return visibility_construction(s.deep_gbuffer);
    }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override {
        return {"gbuffer.depth", "gbuffer.visibility"};
    }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override;
    std::vector<ResourceDesc> outputs(const RenderSettings& s, const FrameFacts& f) const override;
    std::vector<std::string> buffer_inputs(const RenderSettings&, const FrameFacts&) const override {
        return {"visibility_tiles", "visibility_samples"};
    }
    std::vector<std::string> buffer_outputs(const RenderSettings&, const FrameFacts&) const override {
        return {"covered_tiles"};
    }
    void execute(FrameContext& ctx) override;
    // gbuffer_attributes_triangle_records: the triangles' records the frame computed (0: its
    // samples read their triangles themselves).
    void report(const RenderSettings& s, std::map<std::string, double>& stats) const override;
    // The pixels each layer of the last frame covers (Frame.layer_samples); read after the frame.
    std::vector<uint64_t> layer_samples() override;
    void release() override;

private:
    Buffer tiles_, tile_list_, bins_, binned_, sorted_, records_;
    int layers_ = 0;
    size_t records_used_ = 0;
    std::vector<uint64_t> samples_;
    bool samples_read_ = false;
};

}  // namespace ssr
