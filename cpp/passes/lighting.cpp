#include "passes/lighting.h"

#include "passes/compute.h"

namespace ssr {

std::vector<std::string> LightingPass::inputs() const {
    std::vector<std::string> in = {"gbuffer.depth", "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"};
    if (shadows_) in.push_back("shadow_map");
    return in;
}

std::vector<ResourceDesc> LightingPass::outputs(const RenderSettings& s) const {
    return {{"lit", GL_RGBA16F, s.width, s.height, s.layers, 1},
            {"linear_depth", GL_R32F, s.width, s.height, s.layers, 1}};
}

void LightingPass::execute(FrameContext& ctx) {
    Defines d = ctx.defines;
    d["SHADOWS"] = shadows_ ? "1" : "0";
    const GLuint prog = ctx.shaders.program({"passes/lighting.comp"}, d);
    glUseProgram(prog);
    auto& r = ctx.resources;
    glBindTextureUnit(0, r.get("gbuffer.depth").id());
    glBindTextureUnit(1, r.get("gbuffer.albedo").id());
    glBindTextureUnit(2, r.get("gbuffer.normal").id());
    glBindTextureUnit(3, r.get("gbuffer.material").id());
    if (shadows_) glBindTextureUnit(4, r.get("shadow_map").id());
    bind_image_layered(0, r.get("lit"), GL_WRITE_ONLY);
    bind_image_layered(1, r.get("linear_depth"), GL_WRITE_ONLY);
    dispatch_2d(ctx.settings.width, ctx.settings.height, ctx.settings.layers, 8, 8);
}

}  // namespace ssr
