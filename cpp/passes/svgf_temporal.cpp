#include "passes/svgf_temporal.h"

#include "render/pass_registry.h"

#include "passes/compute.h"

namespace ssr {

void SvgfTemporalPass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    const GLuint prog = ctx.shaders.program({"passes/svgf_temporal.comp"}, ctx.defines);
    glUseProgram(prog);
    const bool history = ctx.history && ctx.history->has("svgf.accumulated") && ctx.history->has("svgf.moments");
    glUniform1i(glGetUniformLocation(prog, "u_has_history"), history ? 1 : 0);
    glUniform1i(glGetUniformLocation(prog, "u_max_history"), ctx.settings.svgf_max_history);
    glUniform1i(glGetUniformLocation(prog, "u_mirror_sampling"), ctx.settings.sampling == Sampling::Mirror ? 1 : 0);
    bind_inputs_in_order(r, inputs(ctx.settings, ctx.facts));
    // Without history this frame's reflection stands in (never read: u_has_history = 0).
    glBindTextureUnit(4, history ? ctx.history->get("svgf.accumulated").id() : r.get("reflection").id());
    glBindTextureUnit(5, history ? ctx.history->get("svgf.moments").id() : r.get("reflection").id());
    bind_image_layered(0, r.get("svgf.accumulated"), GL_WRITE_ONLY);
    bind_image_layered(1, r.get("svgf.moments"), GL_WRITE_ONLY);
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 8, 8);
}

SSR_REGISTER_PASS(SvgfTemporalPass());

}  // namespace ssr
