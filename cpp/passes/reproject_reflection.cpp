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
    const FrameResources* h = ctx.history;
    const bool history = h && ctx.history_uniforms && h->has("reflection.hits") && h->has("gbuffer.normal") &&
                         h->has("gbuffer.material");
    // The previous frame's textures by name; without history this frame's stand in (never
    // read: u_has_history = 0).
    NamedUnits units{inputs(s, ctx.facts), {{"reprojection.reflection", GL_WRITE_ONLY}, {"reflection.hits", GL_WRITE_ONLY}}};
    const FrameResources& src = history ? *h : r;
    for (const char* p : {"gbuffer.normal", "gbuffer.material", "reflection.hits"}) {
        units.textures.push_back(std::string("previous.") + p);
        units.own.emplace_back(std::string("previous.") + p, &src.get(p));
    }
    units.add_unit_defines(d);
    const GLuint prog = ctx.shaders.program({"passes/reproject_reflection.comp"}, d);
    glUseProgram(prog);
    (history ? ReprojectPass::history_camera(ctx) : HistoryCamera{}).set(prog);
    const glm::mat4 previous_proj = history ? ctx.history_unjittered_proj : glm::mat4(1.0f);
    glUniformMatrix4fv(glGetUniformLocation(prog, "u_previous_proj"), 1, GL_FALSE, glm::value_ptr(previous_proj));
    glUniform1i(glGetUniformLocation(prog, "u_has_history"), history ? 1 : 0);
    glUniform2f(glGetUniformLocation(prog, "u_jitter"), ctx.jitter_px.x, ctx.jitter_px.y);
    glUniform1f(glGetUniformLocation(prog, "u_reject_normal"), s.reject_normal);
    glUniform1f(glGetUniformLocation(prog, "u_reject_reflection_depth"), s.reject_reflection_depth);
    glUniform1i(glGetUniformLocation(prog, "u_max_history"),
                s.denoise == Denoise::Svgf ? s.svgf_max_history : s.temporal_max_history);
    units.bind_by_name(r, prog, "passes/reproject_reflection.comp");
    dispatch_2d(s.width, s.height, 1, 8, 8);
}

SSR_REGISTER_PASS(ReprojectReflectionPass());

}  // namespace ssr
