#include "passes/reproject_reflection.h"

#include "render/pass_registry.h"

#include <glm/gtc/type_ptr.hpp>

#include "passes/compute.h"
#include "passes/reproject.h"
#include "passes/resolve.h"

namespace ssr {

std::vector<std::string> ReprojectReflectionPass::inputs(const RenderSettings& s, const FrameFacts&) const {
    std::vector<std::string> in = {"rays.hit", "rays.sample", "rays.direction", "linear_depth",
                                   "gbuffer.normal", "gbuffer.material", "reprojection"};
    if (ResolvePass::ray_radiance(s)) in.push_back("rays.radiance");
    return in;
}

void ReprojectReflectionPass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    const RenderSettings& s = ctx.settings;
    Defines d = ctx.defines;
    const bool radiance = ResolvePass::ray_radiance(s);
    d["RAY_RADIANCE"] = radiance ? "1" : "0";
    const GLuint prog = ctx.shaders.program({"passes/reproject_reflection.comp"}, d);
    glUseProgram(prog);
    const FrameResources* h = ctx.history;
    const bool history = h && ctx.history_uniforms && h->has("reflection.hits") && h->has("gbuffer.normal") &&
                         h->has("gbuffer.material");
    (history ? ReprojectPass::history_camera(ctx) : HistoryCamera{}).set(prog);
    const glm::mat4 previous_proj = history ? ctx.history_unjittered_proj : glm::mat4(1.0f);
    glUniformMatrix4fv(glGetUniformLocation(prog, "u_previous_proj"), 1, GL_FALSE, glm::value_ptr(previous_proj));
    glUniform1i(glGetUniformLocation(prog, "u_has_history"), history ? 1 : 0);
    glUniform2f(glGetUniformLocation(prog, "u_jitter"), ctx.jitter_px.x, ctx.jitter_px.y);
    glUniform1f(glGetUniformLocation(prog, "u_reject_normal"), s.reject_normal);
    glUniform1f(glGetUniformLocation(prog, "u_reject_reflection_depth"), s.reject_reflection_depth);
    glUniform1i(glGetUniformLocation(prog, "u_max_history"),
                s.denoise == Denoise::Svgf ? s.svgf_max_history : s.temporal_max_history);
    bind_inputs_in_order(r, inputs(s, ctx.facts));  // units 0-6 (7: rays.radiance)
    // Without history this frame's textures stand in (never read: u_has_history = 0).
    const FrameResources& src = history ? *h : r;
    glBindTextureUnit(8, src.get("gbuffer.normal").id());
    glBindTextureUnit(9, src.get("gbuffer.material").id());
    glBindTextureUnit(10, src.get("reflection.hits").id());
    bind_image_layered(0, r.get("reprojection.reflection"), GL_WRITE_ONLY);
    bind_image_layered(1, r.get("reflection.hits"), GL_WRITE_ONLY);
    dispatch_2d(s.width, s.height, 1, 8, 8);
}

SSR_REGISTER_PASS(ReprojectReflectionPass());

}  // namespace ssr
