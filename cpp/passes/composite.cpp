#include "passes/composite.h"

#include "render/pass_registry.h"

#include "passes/compute.h"
#include "passes/depth_peel.h"

namespace ssr {

NamedUnits CompositePass::units(const FrameContext& ctx, bool bind) const {
    const std::string reflection = reflection_of(ctx.settings, ctx.facts);
    const auto& r = ctx.resources;
    NamedUnits u{{"direct", "gbuffer.material"}, {{"output", GL_WRITE_ONLY}}};
    if (bind) u.own = {{"direct", &r.get(direct_)}, {"output", &r.get(output_)}};
    std::vector<std::string> fetched = {"direct"};
    if (!reflection.empty()) {
        u.textures.insert(u.textures.end(), {"reflection", "gbuffer.albedo", "gbuffer.normal", "linear_depth"});
        if (bind) u.own.emplace_back("reflection", &r.get(reflection));
        if (reads_specular(ctx.settings, ctx.facts)) u.textures.push_back("gbuffer.specular");
        fetched.insert(fetched.end(), {"reflection", "gbuffer.normal", "linear_depth"});
    }
    u.fetch(ctx.fetch_by_image(), fetched);
    return u;
}

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
    units(ctx, false).add_unit_defines(d);
    if (ctx.fetch_by_image()) {
        d["DIRECT_FORMAT"] = image_format_qualifier(ctx.resources.get(direct_).format());
        if (!reflection.empty()) d["REFLECTION_FORMAT"] = image_format_qualifier(ctx.resources.get(reflection).format());
    }
    return d;
}

void CompositePass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    const GLuint prog = ctx.shaders.program({"passes/composite.comp"}, program_defines(ctx));
    glUseProgram(prog);
    units(ctx, true).bind_by_name(r, prog, "passes/composite.comp");
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 8, 8);
}

SSR_REGISTER_PASS(CompositePass());

}  // namespace ssr
