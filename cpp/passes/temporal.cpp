#include "passes/temporal.h"

#include "render/pass_registry.h"

#include "passes/compute.h"

namespace ssr {

void TemporalPass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    const bool history = ctx.history && ctx.history->has("reflection.temporal");
    // The reprojection is the surface's or the reflection's (ReprojectReflectionPass::reprojection);
    // without history this frame's reflection stands in (never read: u_has_history = 0).
    NamedUnits units{{"reflection", "reprojection", "previous.reflection.temporal"},
                     {{"reflection.temporal", GL_WRITE_ONLY}}};
    units.own = {{"reprojection", &r.get(ReprojectReflectionPass::reprojection(ctx.settings))},
                 {"previous.reflection.temporal", history ? &ctx.history->get("reflection.temporal") : &r.get("reflection")}};
    Defines d = ctx.defines;
    units.add_unit_defines(d);
    const GLuint prog = ctx.shaders.program({"passes/temporal.comp"}, d);
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_has_history"), history ? 1 : 0);
    glUniform1i(glGetUniformLocation(prog, "u_max_history"), ctx.settings.temporal_max_history);
    glUniform1f(glGetUniformLocation(prog, "u_clamp_gamma"), ctx.settings.temporal_clamp);
    units.bind_by_name(r, prog, "passes/temporal.comp");
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 8, 8);
}

SSR_REGISTER_PASS(TemporalPass());

}  // namespace ssr
