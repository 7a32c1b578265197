#include "passes/svgf_variance.h"

#include "render/pass_registry.h"

#include "passes/compute.h"

namespace ssr {

void SvgfVariancePass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    const NamedUnits units{inputs(ctx.settings, ctx.facts), {{"svgf.variance", GL_WRITE_ONLY}, {"svgf.guide", GL_WRITE_ONLY}}};
    Defines d = ctx.defines;
    units.add_unit_defines(d);
    const GLuint prog = ctx.shaders.program({"passes/svgf_variance.comp"}, d);
    glUseProgram(prog);
    glUniform1f(glGetUniformLocation(prog, "u_sigma_depth"), ctx.settings.svgf_sigma_depth);
    glUniform1f(glGetUniformLocation(prog, "u_sigma_normal"), ctx.settings.svgf_sigma_normal);
    glUniform1i(glGetUniformLocation(prog, "u_mirror_sampling"), ctx.settings.sampling == Sampling::Mirror ? 1 : 0);
    units.bind_by_name(r);
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 8, 8);
}

SSR_REGISTER_PASS(SvgfVariancePass());

}  // namespace ssr
