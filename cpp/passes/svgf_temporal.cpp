#include "passes/svgf_temporal.h"

#include "render/pass_registry.h"

#include "passes/compute.h"

namespace ssr {

void SvgfTemporalPass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    const bool history = ctx.history && ctx.history->has("svgf.accumulated") && ctx.history->has("svgf.moments");
    // The reprojection is the surface's or the reflection's (ReprojectReflectionPass::reprojection),
    // read as "reprojection"; without history this frame's reflection stands in for the previous
    // frame's textures (never read: u_has_history = 0).
    NamedUnits units{{"reflection", "reprojection", "gbuffer.normal", "gbuffer.material", "previous.svgf.accumulated",
                      "previous.svgf.moments"},
                     {{"svgf.accumulated", GL_WRITE_ONLY}, {"svgf.moments", GL_WRITE_ONLY}}};
    units.own = {{"reprojection", &r.get(ReprojectReflectionPass::reprojection(ctx.settings))},
                 {"previous.svgf.accumulated", history ? &ctx.history->get("svgf.accumulated") : &r.get("reflection")},
                 {"previous.svgf.moments", history ? &ctx.history->get("svgf.moments") : &r.get("reflection")}};
    Defines d = ctx.defines;
    units.add_unit_defines(d);
    const GLuint prog = ctx.shaders.program({"passes/svgf_temporal.comp"}, d);
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_has_history"), history ? 1 : 0);
    glUniform1i(glGetUniformLocation(prog, "u_max_history"), ctx.settings.svgf_max_history);
    glUniform1i(glGetUniformLocation(prog, "u_mirror_sampling"), ctx.settings.sampling == Sampling::Mirror ? 1 : 0);
    units.bind_by_name(r, prog, "passes/svgf_temporal.comp");
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 8, 8);
}

SSR_REGISTER_PASS(SvgfTemporalPass());

}  // namespace ssr
