#include "passes/svgf_variance.h"

#include "render/pass_registry.h"

#include "passes/compute.h"

namespace ssr {

void SvgfVariancePass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    const GLuint prog = ctx.shaders.program({"passes/svgf_variance.comp"}, ctx.defines);
    glUseProgram(prog);
    glUniform1f(glGetUniformLocation(prog, "u_sigma_depth"), ctx.settings.svgf_sigma_depth);
    glUniform1f(glGetUniformLocation(prog, "u_sigma_normal"), ctx.settings.svgf_sigma_normal);
    glUniform1i(glGetUniformLocation(prog, "u_mirror_sampling"), ctx.settings.sampling == Sampling::Mirror ? 1 : 0);
    bind_inputs_in_order(r, inputs(ctx.settings, ctx.facts));
    bind_image_layered(0, r.get("svgf.variance"), GL_WRITE_ONLY);
    bind_image_layered(1, r.get("svgf.guide"), GL_WRITE_ONLY);
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 8, 8);
}

SSR_REGISTER_PASS(SvgfVariancePass());

}  // namespace ssr
