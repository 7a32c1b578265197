#include "passes/resolve.h"

#include "passes/compute.h"

namespace ssr {

void ResolvePass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    // bounces="history" (seed 002, 4.6.4): hits fetch the previous frame's final colour.
    const bool bounce_history = ctx.settings.bounces == Bounces::History;
    Defines d = ctx.defines;
    d["BOUNCES_HISTORY"] = bounce_history ? "1" : "0";
    const GLuint prog = ctx.shaders.program({"passes/resolve.comp"}, d);
    glUseProgram(prog);
    if (bounce_history) {
        const bool history = ctx.history && ctx.history->has("color");
        glUniform1i(glGetUniformLocation(prog, "u_has_history"), history ? 1 : 0);
        glBindTextureUnit(8, r.get("reprojection").id());
        glBindTextureUnit(9, history ? ctx.history->get("color").id() : r.get("reprojection").id());
    }
    const char* inputs[] = {"rays.hit", "rays.sample", "rays.direction", "lit", "linear_depth",
                            "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"};
    for (GLuint unit = 0; unit < 8; ++unit) glBindTextureUnit(unit, r.get(inputs[unit]).id());
    bind_image_layered(0, r.get("reflection"), GL_WRITE_ONLY);
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 16, 16);
}

}  // namespace ssr
