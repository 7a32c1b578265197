#include "passes/taa.h"

#include "render/pass_registry.h"

#include "passes/compute.h"

namespace ssr {

void TaaPass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    Defines d = ctx.defines;
    const bool thesis = ctx.settings.taa == TaaMode::Thesis;
    d["TAA_THESIS"] = thesis ? "1" : "0";
    // The thesis blends with the previous frame's own colour; the clamped TAA with its output.
    const char* history_name = thesis ? "color" : "color.taa";
    const bool history = ctx.history && ctx.history->has(history_name);
    // "previous.color": that previous colour, or without history this frame's (never read:
    // u_has_history = 0).
    NamedUnits units{{"color", "previous.color"}, {{"color.taa", GL_WRITE_ONLY}}};
    if (!thesis) units.textures.push_back("reprojection");
    units.own = {{"previous.color", history ? &ctx.history->get(history_name) : &r.get("color")}};
    units.add_unit_defines(d);
    const GLuint prog = ctx.shaders.program({"passes/taa.comp"}, d);
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_has_history"), history ? 1 : 0);
    glUniform1f(glGetUniformLocation(prog, "u_history_weight"), ctx.settings.taa_history_weight);
    units.bind_by_name(r, prog, "passes/taa.comp");
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 8, 8);
}

SSR_REGISTER_PASS(TaaPass());

}  // namespace ssr
