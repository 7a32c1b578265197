// lighting: shades every G-buffer layer with direct light, the shadow map and a constant
// ambient term (shaders/lib/shading.glsl), and writes each layer's linear view depth.
//   inputs : gbuffer.depth, gbuffer.albedo, gbuffer.normal, gbuffer.material, shadow_map
//            (when shadows are on), gbuffer.emission (when the scene has an emissive texture),
//            gbuffer.specular (when it has a KHR_materials_specular texture)
//   outputs: lit (RGBA16F array: radiance per layer; alpha 0.5 + r / 2 where a surface
//            covers the texel, r its reflectivity, and 0 where none does), linear_depth (R32F array: positive
//            view-space depth per layer; the far-plane distance where nothing is covered)
// It runs over the 8x8 tiles the peeling covered (the buffer "covered_tiles"); every other texel
// is cleared to those "nothing here" values instead of shaded.
#pragma once

#include "passes/depth_peel.h"
#include "render/render_pass.h"

namespace ssr {

class LightingPass : public RenderPass {
public:
    // With or without the shadow map (FrameFacts.shadows): a define of one program (SHADOWS).
    std::string name() const override { return "lighting"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return true; }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override;
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override;
    std::vector<std::string> buffer_inputs(const RenderSettings&, const FrameFacts&) const override {
        return {"covered_tiles"};
    }
    void execute(FrameContext& ctx) override;
    // Layers the last run counted as shaded: with Settings.skip those the peeling found non-empty.
    int layers_shaded() const { return layers_shaded_; }
    // 8x8 tiles the last run shaded from the covered-tile list (read back from the GPU).
    int tiles_shaded() const;
    // layers_lit; with skip's counters, the 8x8 tiles shaded.
    void report(const RenderSettings& s, std::map<std::string, double>& stats) const override {
        stats["layers_lit"] = double(layers_shaded_);
        if (s.skip) stats["tiles_lit"] = double(tiles_shaded());
    }

private:
    int layers_shaded_ = 0;
    const Buffer* tiles_ = nullptr;  // the covered-tile list the last run used
};

}  // namespace ssr
