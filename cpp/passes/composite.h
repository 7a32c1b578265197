// composite: the final image (shaders/passes/composite.comp).
//   inputs : lit, gbuffer.material; with reflections also reflection, gbuffer.albedo,
//            gbuffer.normal, linear_depth
//   outputs: color (RGBA32F, linear radiance)
// Layer 0's lit colour, blended with the reflection (Settings.composite: the thesis's linear
// blend or Fresnel-weighted), where a surface covers the pixel; the environment elsewhere.
#pragma once

#include "render/render_pass.h"

namespace ssr {

class CompositePass : public RenderPass {
public:
    // `reflection` and `output` name the textures read and written (the reference composites
    // its own reflection into reference.color with the same code).
    // `direct` names the surfaces' own light (the reference's exact reference.direct).
    explicit CompositePass(bool reflections, std::string reflection = "reflection", std::string output = "color",
                           std::string direct = "lit")
        : reflections_(reflections), reflection_(std::move(reflection)), output_(std::move(output)),
          direct_(std::move(direct)) {}
    std::string name() const override { return output_ == "color" ? "composite" : "composite." + output_; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override {
        // One composite a frame, of the last reflection the chain made: denoised, accumulated, resolved, or none.
        const bool svgf = f.reflections && s.denoise == Denoise::Svgf;
        const bool temporal = f.reflections && s.temporal_reflections;
        const std::string last = svgf ? "reflection.denoised" : temporal ? "reflection.temporal" : "reflection";
        return output_ == "color" && (reflections_ ? f.reflections && reflection_ == last : !f.reflections);
    }
    std::vector<std::string> inputs() const override {
        if (!reflections_) return {direct_, "gbuffer.material"};
        return {direct_, "gbuffer.material", reflection_, "gbuffer.albedo", "gbuffer.normal", "linear_depth"};
    }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{output_, GL_RGBA32F, s.width, s.height, 0, 1}};
    }
    void execute(FrameContext& ctx) override;
    // The defines its program is compiled with (the reference precompiles it before timing).
    Defines program_defines(const FrameContext& ctx) const;

private:
    bool reflections_;
    std::string reflection_, output_, direct_;
};

}  // namespace ssr
