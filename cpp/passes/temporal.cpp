#include "passes/temporal.h"

#include "render/pass_registry.h"

#include "passes/compute.h"

namespace ssr {

void TemporalPass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    const GLuint prog = ctx.shaders.program({"passes/temporal.comp"}, ctx.defines);
    glUseProgram(prog);
    const bool history = ctx.history && ctx.history->has("reflection.temporal");
    glUniform1i(glGetUniformLocation(prog, "u_has_history"), history ? 1 : 0);
    glUniform1i(glGetUniformLocation(prog, "u_max_history"), ctx.settings.temporal_max_history);
    glUniform1f(glGetUniformLocation(prog, "u_clamp_gamma"), ctx.settings.temporal_clamp);
    glBindTextureUnit(0, r.get("reflection").id());
    glBindTextureUnit(1, r.get(ReprojectReflectionPass::reprojection(ctx.settings)).id());
    // Without history this frame's reflection stands in (never read: u_has_history = 0).
    glBindTextureUnit(2, history ? ctx.history->get("reflection.temporal").id() : r.get("reflection").id());
    bind_image_layered(0, r.get("reflection.temporal"), GL_WRITE_ONLY);
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 8, 8);
}

SSR_REGISTER_PASS(TemporalPass());

}  // namespace ssr
