#include "passes/svgf_atrous.h"

#include "render/pass_registry.h"

#include "passes/compute.h"

namespace ssr {

void SvgfAtrousPass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    const RenderSettings& s = ctx.settings;
    const GLuint prog = ctx.shaders.program({"passes/svgf_atrous.comp"}, ctx.defines);
    glUseProgram(prog);
    glUniform1f(glGetUniformLocation(prog, "u_sigma_depth"), s.svgf_sigma_depth);
    glUniform1f(glGetUniformLocation(prog, "u_sigma_normal"), s.svgf_sigma_normal);
    glUniform1f(glGetUniformLocation(prog, "u_sigma_luminance"), s.svgf_sigma_luminance);
    bind_inputs_in_order(r, inputs(ctx.settings, ctx.facts));
    // Iterations ping-pong between svgf.atrous and reflection.denoised, arranged so that the
    // last one writes reflection.denoised; 0 iterations copy the variance pass's colour.
    const int iterations = s.svgf_iterations;
    const GLint step_loc = glGetUniformLocation(prog, "u_step");
    if (iterations == 0) {
        glUniform1i(step_loc, 0);
        bind_image_layered(0, r.get("reflection.denoised"), GL_WRITE_ONLY);
        dispatch_2d(s.width, s.height, 1, 8, 8);
        return;
    }
    const Texture* src = &r.get("svgf.variance");
    for (int i = 0; i < iterations; ++i) {
        Texture& dst = r.get((iterations - 1 - i) % 2 == 0 ? "reflection.denoised" : "svgf.atrous");
        glUniform1i(step_loc, 1 << i);
        glBindTextureUnit(0, src->id());
        bind_image_layered(0, dst, GL_WRITE_ONLY);
        dispatch_2d(s.width, s.height, 1, 8, 8);
        src = &dst;
    }
}

SSR_REGISTER_PASS(SvgfAtrousPass());

}  // namespace ssr
