#include "passes/reproject.h"

#include <glm/gtc/type_ptr.hpp>

#include "passes/compute.h"

namespace ssr {

void ReprojectPass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    const GLuint prog = ctx.shaders.program({"passes/reproject.comp"}, ctx.defines);
    glUseProgram(prog);
    const bool history = ctx.history && ctx.history_uniforms && ctx.history->has("linear_depth") &&
                         ctx.history->has("gbuffer.normal") && ctx.history->has("gbuffer.material");
    // VP_prev * V_curr^-1 and V_curr * V_prev^-1, formed in double precision so that a static
    // camera reprojects to itself to float rounding (seed 002, Listing 4.9).
    glm::mat4 to_prev_clip(1.0f), prev_to_view(1.0f);
    if (history) {
        const FrameUniforms& h = *ctx.history_uniforms;
        const glm::dmat4 prev_vp = glm::dmat4(ctx.history_unjittered_proj) * glm::dmat4(h.view);
        to_prev_clip = glm::mat4(prev_vp * glm::inverse(glm::dmat4(ctx.uniforms.view)));
        prev_to_view = glm::mat4(glm::dmat4(ctx.uniforms.view) * glm::inverse(glm::dmat4(h.view)));
    }
    glUniformMatrix4fv(glGetUniformLocation(prog, "u_view_to_previous_clip"), 1, GL_FALSE, glm::value_ptr(to_prev_clip));
    glUniformMatrix4fv(glGetUniformLocation(prog, "u_previous_view_to_view"), 1, GL_FALSE, glm::value_ptr(prev_to_view));
    glUniform1i(glGetUniformLocation(prog, "u_has_history"), history ? 1 : 0);
    glUniform2f(glGetUniformLocation(prog, "u_jitter"), ctx.jitter_px.x, ctx.jitter_px.y);
    glUniform1f(glGetUniformLocation(prog, "u_reject_depth"), ctx.settings.reject_depth);
    glUniform1f(glGetUniformLocation(prog, "u_reject_normal"), ctx.settings.reject_normal);
    glUniform1i(glGetUniformLocation(prog, "u_reject_offscreen"), ctx.settings.reject_offscreen ? 1 : 0);
    glBindTextureUnit(0, r.get("linear_depth").id());
    glBindTextureUnit(1, r.get("gbuffer.normal").id());
    glBindTextureUnit(2, r.get("gbuffer.material").id());
    // Without history the current frame's textures stand in (never read: u_has_history = 0).
    const FrameResources& h = history ? *ctx.history : r;
    glBindTextureUnit(3, h.get("linear_depth").id());
    glBindTextureUnit(4, h.get("gbuffer.normal").id());
    glBindTextureUnit(5, h.get("gbuffer.material").id());
    bind_image_layered(0, r.get("reprojection"), GL_WRITE_ONLY);
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 8, 8);
}

}  // namespace ssr
