#include "passes/taa.h"

#include "render/pass_registry.h"

#include "passes/compute.h"

namespace ssr {

void TaaPass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    Defines d = ctx.defines;
    const bool thesis = ctx.settings.taa == TaaMode::Thesis;
    d["TAA_THESIS"] = thesis ? "1" : "0";
    const GLuint prog = ctx.shaders.program({"passes/taa.comp"}, d);
    glUseProgram(prog);
    // The thesis blends with the previous frame's own colour; the clamped TAA with its output.
    const char* history_name = thesis ? "color" : "color.taa";
    const bool history = ctx.history && ctx.history->has(history_name);
    glUniform1i(glGetUniformLocation(prog, "u_has_history"), history ? 1 : 0);
    glUniform1f(glGetUniformLocation(prog, "u_history_weight"), ctx.settings.taa_history_weight);
    glBindTextureUnit(0, r.get("color").id());
    if (!thesis) glBindTextureUnit(1, r.get("reprojection").id());
    glBindTextureUnit(2, history ? ctx.history->get(history_name).id() : r.get("color").id());
    bind_image_layered(0, r.get("color.taa"), GL_WRITE_ONLY);
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 8, 8);
}

SSR_REGISTER_PASS(TaaPass());

}  // namespace ssr
