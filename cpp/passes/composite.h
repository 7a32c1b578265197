// composite: the final image (shaders/passes/composite.comp).
//   inputs : lit, gbuffer.material; with reflections also reflection, gbuffer.albedo,
//            gbuffer.normal, linear_depth; gbuffer.specular for the PBR composite of a scene with
//            a specular texture (FrameFacts::specular_texture)
//   outputs: color (RGBA32F, linear radiance)
// Layer 0's lit colour, blended with the reflection (Settings.composite: the thesis's linear
// blend or Fresnel-weighted), where a surface covers the pixel; the environment elsewhere.
#pragma once

#include "passes/compute.h"
#include "render/render_pass.h"

namespace ssr {

class CompositePass : public RenderPass {
public:
    // The frame's composite: of the last reflection the chain made (denoised, accumulated,
    // resolved) or of none, chosen from the settings and facts (the REFLECTIONS define and the
    // texture it reads), one object for every variant.
    CompositePass() = default;
    // A fixed composite: `reflection` and `output` name the textures read and written (the
    // reference composites its own reflection into reference.color with the same code).
    // `direct` names the surfaces' own light (the reference's exact reference.direct).
    CompositePass(bool reflections, std::string reflection, std::string output, std::string direct)
        : fixed_(true), reflections_(reflections), reflection_(std::move(reflection)), output_(std::move(output)),
          direct_(std::move(direct)) {}
    std::string name() const override { return output_ == "color" ? "composite" : "composite." + output_; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return !fixed_; }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override {
        const std::string reflection = reflection_of(s, f);
        if (reflection.empty()) return {direct_, "gbuffer.material"};
        std::vector<std::string> in = {direct_, "gbuffer.material", reflection, "gbuffer.albedo", "gbuffer.normal",
                                       "linear_depth"};
        if (reads_specular(s, f)) in.push_back("gbuffer.specular");  // F0 per texel (lib/gbuffer_specular.glsl)
        return in;
    }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {{output_, GL_RGBA32F, s.width, s.height, 0, 1}};
    }
    void execute(FrameContext& ctx) override;
    // The defines its program is compiled with (the reference precompiles it before timing).
    Defines program_defines(const FrameContext& ctx) const;
    // Its textures and images by name: the direct light as "direct", the chain's reflection as
    // "reflection", the target as "output" (the float inputs by imageLoad on the CPU device);
    // `bind`: with the textures those names stand for (else the names only, for the defines).
    NamedUnits units(const FrameContext& ctx, bool bind) const;

private:
    // The reflection it composites ("" for none).
    std::string reflection_of(const RenderSettings& s, const FrameFacts& f) const {
        if (fixed_) return reflections_ ? reflection_ : "";
        if (!f.reflections) return "";
        return s.denoise == Denoise::Svgf ? "reflection.denoised"
               : s.temporal_reflections  ? "reflection.temporal"
                                         : "reflection";
    }
    // The PBR composite's F0 from gbuffer.specular (a scene with a specular texture).
    static bool reads_specular(const RenderSettings& s, const FrameFacts& f) {
        return s.composite == CompositeMode::Pbr && f.specular_texture;
    }
    bool fixed_ = false;
    bool reflections_ = true;
    std::string reflection_ = "reflection", output_ = "color", direct_ = "lit";
};

}  // namespace ssr
