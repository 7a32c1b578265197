#include "passes/reproject.h"

#include "render/pass_registry.h"

#include <glm/gtc/type_ptr.hpp>

#include "passes/compute.h"

namespace ssr {

HistoryCamera ReprojectPass::history_camera(const FrameContext& ctx) {
    HistoryCamera c;
    if (!ctx.history_uniforms) return c;
    const glm::dmat4 view(ctx.uniforms.view), previous_view(ctx.history_uniforms->view);
    c.view_to_previous_clip = glm::mat4(glm::dmat4(ctx.history_unjittered_proj) * previous_view * glm::inverse(view));
    c.previous_view_to_view = glm::mat4(view * glm::inverse(previous_view));
    c.view_to_previous_view = glm::mat4(previous_view * glm::inverse(view));
    return c;
}

void HistoryCamera::set(GLuint prog) const {
    glUniformMatrix4fv(glGetUniformLocation(prog, "u_view_to_previous_clip"), 1, GL_FALSE, glm::value_ptr(view_to_previous_clip));
    glUniformMatrix4fv(glGetUniformLocation(prog, "u_previous_view_to_view"), 1, GL_FALSE, glm::value_ptr(previous_view_to_view));
    glUniformMatrix4fv(glGetUniformLocation(prog, "u_view_to_previous_view"), 1, GL_FALSE, glm::value_ptr(view_to_previous_view));
}

ResourceDesc ReprojectPass::texture(const std::string& name, const RenderSettings& s) {
    using D = ChannelDecode;
    return ResourceDesc{name, GL_RGBA32F, s.width, s.height, 0, 1}.with(
        {{"reprojection", "pixel", 0, 2, D::WindowPoint,
          "previous-frame position in pixels (column, row from the top; pixel centres at .5)"},
         {"reprojection", "valid", 2, 1, D::Flag, "the history there is kept"},
         {"reprojection", "reason", 3, 1, D::Integer,
          "0 valid, 1 no history (first frame), 2 no surface, 3 off-screen, 4 another surface there, 5 normal "
          "differs, 6 disoccluded, 7 the reflection there lay elsewhere"}});
}

void ReprojectPass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    const bool history = ctx.history && ctx.history_uniforms && ctx.history->has("linear_depth") &&
                         ctx.history->has("gbuffer.normal") && ctx.history->has("gbuffer.material");
    // The previous frame's textures by name; without history the current frame's stand in
    // (never read: u_has_history = 0).
    NamedUnits units{{"linear_depth", "gbuffer.normal", "gbuffer.material", "gbuffer.motion"},
                     {{"reprojection", GL_WRITE_ONLY}}};
    const FrameResources& h = history ? *ctx.history : r;
    for (const char* p : {"linear_depth", "gbuffer.normal", "gbuffer.material"}) {
        units.textures.push_back(std::string("previous.") + p);
        units.own.emplace_back(std::string("previous.") + p, &h.get(p));
    }
    Defines d = ctx.defines;
    units.add_unit_defines(d);
    const GLuint prog = ctx.shaders.program({"passes/reproject.comp"}, d);
    glUseProgram(prog);
    (history ? history_camera(ctx) : HistoryCamera{}).set(prog);
    glUniform1i(glGetUniformLocation(prog, "u_reject_layers"), ctx.settings.reject_layers ? 1 : 0);
    glUniform1i(glGetUniformLocation(prog, "u_has_history"), history ? 1 : 0);
    glUniform2f(glGetUniformLocation(prog, "u_jitter"), ctx.jitter_px.x, ctx.jitter_px.y);
    glUniform1f(glGetUniformLocation(prog, "u_reject_depth"), ctx.settings.reject_depth);
    glUniform1f(glGetUniformLocation(prog, "u_reject_normal"), ctx.settings.reject_normal);
    glUniform1i(glGetUniformLocation(prog, "u_reject_offscreen"), ctx.settings.reject_offscreen ? 1 : 0);
    units.bind_by_name(r, prog, "passes/reproject.comp");
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 8, 8);
}

SSR_REGISTER_PASS(ReprojectPass());

}  // namespace ssr
