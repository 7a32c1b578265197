#include "passes/svgf_atrous.h"

#include "render/pass_registry.h"

#include "passes/compute.h"

namespace ssr {

void SvgfAtrousPass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    const RenderSettings& s = ctx.settings;
    // Each iteration reads the last one's output: "atrous.input" and "atrous.output" name the
    // ping-pong's two ends, svgf.variance and reflection.denoised to begin with.
    NamedUnits units{{"atrous.input", "svgf.guide"}, {{"atrous.output", GL_WRITE_ONLY}}};
    units.own = {{"atrous.input", &r.get("svgf.variance")}, {"atrous.output", &r.get("reflection.denoised")}};
    Defines d = ctx.defines;
    units.add_unit_defines(d);
    const GLuint prog = ctx.shaders.program({"passes/svgf_atrous.comp"}, d);
    glUseProgram(prog);
    glUniform1f(glGetUniformLocation(prog, "u_sigma_depth"), s.svgf_sigma_depth);
    glUniform1f(glGetUniformLocation(prog, "u_sigma_normal"), s.svgf_sigma_normal);
    glUniform1f(glGetUniformLocation(prog, "u_sigma_luminance"), s.svgf_sigma_luminance);
    units.bind_by_name(r, prog, "passes/svgf_atrous.comp");
    // Iterations ping-pong between svgf.atrous and reflection.denoised, arranged so that the
    // last one writes reflection.denoised; 0 iterations copy the variance pass's colour.
    const int iterations = s.svgf_iterations;
    const GLint step_loc = glGetUniformLocation(prog, "u_step");
    if (iterations == 0) {
        glUniform1i(step_loc, 0);
        dispatch_2d(s.width, s.height, 1, 8, 8);
        return;
    }
    const Texture* src = &r.get("svgf.variance");
    for (int i = 0; i < iterations; ++i) {
        Texture& dst = r.get((iterations - 1 - i) % 2 == 0 ? "reflection.denoised" : "svgf.atrous");
        glUniform1i(step_loc, 1 << i);
        glBindTextureUnit(units.texture_unit("atrous.input"), src->id());
        bind_image_layered(units.image_unit("atrous.output"), dst, GL_WRITE_ONLY);
        dispatch_2d(s.width, s.height, 1, 8, 8);
        src = &dst;
    }
}

SSR_REGISTER_PASS(SvgfAtrousPass());

}  // namespace ssr
