#include "passes/composite.h"

#include "render/pass_registry.h"

#include "passes/compute.h"
#include "passes/depth_peel.h"

namespace ssr {

Defines CompositePass::program_defines(const FrameContext& ctx) const {
    const std::string reflection = reflection_of(ctx.settings, ctx.facts);
    Defines d = ctx.defines;
    d["REFLECTIONS"] = reflection.empty() ? "0" : "1";
    // The formula is compiled in, not chosen per pixel from the settings block: on
    // llvmpipe the unused pbr branch (its table fetch and material lookups) cost 2.5x the pass.
    d["PBR_COMPOSITE"] = ctx.settings.composite == CompositeMode::Pbr ? "1" : "0";
    if (!reflection.empty() && reads_specular(ctx.settings, ctx.facts)) d["SPECULAR_TEXTURE"] = "1";
    // The lighting pass's lit colour carries coverage and r in its alpha (lighting.h),
    // which saves the material fetch; another direct light (the reference's) does not.
    d["LIT_CARRIES_R"] = direct_ == "lit" ? "1" : "0";
    // FETCH_BY_IMAGE (lib/input_fetch.glsl): the direct light and the reflection are read
    // by imageLoad, whose format qualifier depends on the chain (lit RGBA16F, the reference's and
    // the temporal passes' RGBA32F).
    if (ctx.fetch_by_image()) {
        d["DIRECT_FORMAT"] = image_format_qualifier(ctx.resources.get(direct_).format());
        if (!reflection.empty()) d["REFLECTION_FORMAT"] = image_format_qualifier(ctx.resources.get(reflection).format());
    }
    return d;
}

void CompositePass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    const std::string reflection = reflection_of(ctx.settings, ctx.facts);
    const bool reflections = !reflection.empty();
    glUseProgram(ctx.shaders.program({"passes/composite.comp"}, program_defines(ctx)));
    glBindTextureUnit(0, r.get(direct_).id());
    glBindTextureUnit(1, r.get("gbuffer.material").id());
    if (reflections) {
        glBindTextureUnit(2, r.get(reflection).id());
        glBindTextureUnit(3, r.get("gbuffer.albedo").id());
        glBindTextureUnit(4, r.get("gbuffer.normal").id());
        glBindTextureUnit(5, r.get("linear_depth").id());
        if (reads_specular(ctx.settings, ctx.facts)) glBindTextureUnit(DepthPeelPass::kSpecularUnit, r.get("gbuffer.specular").id());
    }
    bind_image_layered(0, ctx.resources.get(output_), GL_WRITE_ONLY);
    if (ctx.fetch_by_image()) {  // image units 1-4 (lib/input_fetch.glsl)
        bind_input_images(r, 1, {direct_});
        if (reflections) bind_input_images(r, 2, {reflection, "gbuffer.normal", "linear_depth"});
    }
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 8, 8);
}

SSR_REGISTER_PASS(CompositePass());

}  // namespace ssr
