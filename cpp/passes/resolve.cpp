#include "passes/resolve.h"

#include "render/pass_registry.h"

#include <glm/gtc/type_ptr.hpp>

#include "core/errors.h"
#include "passes/classify.h"
#include "passes/compute.h"
#include "passes/reproject.h"
#include "passes/specular_occlusion.h"

namespace ssr {

bool ResolvePass::ray_radiance(const RenderSettings& s) {
    return s.method == TraceMethod::Bvh || s.fallback == Fallback::Bvh || s.fallback == Fallback::Probes ||
           SpecularOcclusionPass::enabled(s);
}

Defines ResolvePass::ray_defines(const FrameContext& ctx) {
    const RenderSettings& s = ctx.settings;
    Defines d = ctx.defines;
    // bounces="history" (seed 002, 4.6.4): hits fetch the previous frame's final colour.
    d["BOUNCES_HISTORY"] = s.bounces == Bounces::History ? "1" : "0";
    d["RAY_RADIANCE"] = ray_radiance(s) ? "1" : "0";
    // The BVH's radiance is exact: a faded hit it retraced takes it whole (a probe's is an
    // approximation, blended with the faded hit as the environment is).
    d["RAY_RADIANCE_EXACT"] = s.method == TraceMethod::Bvh || s.fallback == Fallback::Bvh ? "1" : "0";
    // fallback "none" lets unresolved rays bring nothing instead of the environment.
    d["FALLBACK_NONE"] = s.method != TraceMethod::Bvh && s.fallback == Fallback::None ? "1" : "0";
    return d;
}

NamedUnits ResolvePass::ray_units(const FrameContext& ctx) {
    const auto& r = ctx.resources;
    NamedUnits u{{"rays.hit", "rays.sample", "rays.direction", "lit", "linear_depth", "gbuffer.albedo", "gbuffer.normal",
                  "gbuffer.material"},
                 {}};
    std::vector<std::string> fetched = {"rays.hit", "rays.sample", "rays.direction", "lit", "linear_depth", "gbuffer.normal"};
    if (ray_radiance(ctx.settings)) {
        u.textures.push_back("rays.radiance");
        fetched.push_back("rays.radiance");
    }
    if (ctx.settings.bounces == Bounces::History) {
        const bool history = ctx.history && ctx.history->has("color");
        u.textures.insert(u.textures.end(), {"reprojection", "previous.color"});
        // Without history the reprojection stands in (never read: u_has_history = 0).
        u.own = {{"previous.color", history ? &ctx.history->get("color") : &r.get("reprojection")}};
    }
    u.fetch(ctx.fetch_by_image(), fetched);
    return u;
}

void ResolvePass::bind_ray_inputs(FrameContext& ctx, GLuint prog, const NamedUnits& units, const std::string& shader) {
    if (ctx.settings.bounces == Bounces::History) {
        const bool history = ctx.history && ctx.history->has("color");
        glUniform1i(glGetUniformLocation(prog, "u_has_history"), history ? 1 : 0);
    }
    units.bind_by_name(ctx.resources, prog, shader);
}

bool ResolvePass::shared_tile(const RenderSettings& s, bool fetch_by_image) {
    return !own_rays_only(s) && !fetch_by_image;
}

std::vector<std::string> ResolvePass::buffer_inputs(const RenderSettings& s, const FrameFacts&) const {
    if (ClassifyPass::resolves_over_lists(s)) return {"resolve_list"};
    return {};
}

std::vector<std::string> ResolvePass::ray_inputs(const RenderSettings& s) {
    std::vector<std::string> in{"rays.hit", "rays.sample", "rays.direction", "lit", "linear_depth",
                                "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"};
    if (ray_radiance(s)) in.push_back("rays.radiance");
    if (s.bounces == Bounces::History) in.push_back("reprojection");
    return in;
}

std::vector<std::string> ResolvePass::inputs(const RenderSettings& s, const FrameFacts& f) const {
    std::vector<std::string> in = ray_inputs(s);
    if (!own_rays_only(s) && !shared_tile(s, f.fetch_by_image)) {
        in.push_back("resolve.ray_color");
        in.push_back("resolve.ray_target");
    }
    if (s.temporal_ray_reuse && s.bounces != Bounces::History) in.push_back("reprojection");
    return in;
}

std::vector<ResourceDesc> ResolvePass::outputs(const RenderSettings& s) const {
    if (ClassifyPass::resolves_over_lists(s)) return {};
    return {reflection_texture(s)};
}

std::vector<std::string> ResolvePass::rewrites(const RenderSettings& s, const FrameFacts&) const {
    if (ClassifyPass::resolves_over_lists(s)) return {"reflection"};
    return {};
}

void ResolvePass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    Defines d = ray_defines(ctx);
    // Ray-result reuse over time (seed 000, 4.4): the previous frame's rays of the same trace grid.
    const bool ray_reuse = ctx.settings.temporal_ray_reuse;
    d["TEMPORAL_RAY_REUSE"] = ray_reuse ? "1" : "0";
    // Own rays only (own_rays_only in resolve.h): no shared tile, no barriers.
    const RenderSettings& s = ctx.settings;
    const bool own_rays_only = ResolvePass::own_rays_only(s);
    d["OWN_RAYS_ONLY"] = own_rays_only ? "1" : "0";
    // Over the classify pass's resolve list (receiving pixels, or tiles holding one).
    const bool list = ClassifyPass::resolves_over_lists(s);
    d["RESOLVE_LIST"] = list ? "1" : "0";
    d["RESOLVE_LIST_PIXELS"] = list && own_rays_only ? "1" : "0";
    // Neighbours' rays from the shared tile, or from resolve_fetch's textures where the
    // passes read by imageLoad (llvmpipe's shared-memory loads are slow; resolve_fetch.h).
    const bool shared = shared_tile(s, ctx.fetch_by_image());
    d["RESOLVE_SHARED_TILE"] = shared ? "1" : "0";
    NamedUnits units = ray_units(ctx);
    units.images.emplace_back("reflection", GL_WRITE_ONLY);
    if (!shared && !own_rays_only)
        units.images.insert(units.images.end(), {{"resolve.ray_color", GL_READ_ONLY}, {"resolve.ray_target", GL_READ_ONLY}});
    // The previous frame's rays (TEXTURE_PREVIOUS_RAYS_HIT, ...), this frame's standing in
    // without history (never read: u_has_previous_rays = 0).
    const char* prev[] = {"rays.hit", "rays.sample", "rays.direction", "lit", "linear_depth", "gbuffer.normal",
                          "gbuffer.material"};
    const FrameResources* h = ctx.history;
    const bool history = ray_reuse && h && ctx.history_uniforms && h->has("rays.hit") && h->has("lit") &&
                         h->get("rays.hit").width() == r.get("rays.hit").width() &&
                         h->get("rays.hit").height() == r.get("rays.hit").height() &&
                         h->get("lit").layers() == r.get("lit").layers();
    if (ray_reuse) {
        if (ctx.settings.bounces != Bounces::History) units.textures.push_back("reprojection");
        const FrameResources& src = history ? *h : r;
        for (const char* p : prev) {
            units.textures.push_back(std::string("previous.") + p);
            units.own.emplace_back(std::string("previous.") + p, &src.get(p));
        }
    }
    units.add_unit_defines(d);
    const GLuint prog = ctx.shaders.program({"passes/resolve.comp"}, d);
    glUseProgram(prog);
    if (ray_reuse) {
        glm::vec4 prev_proj(1.0f, 1.0f, 0.0f, 0.0f);
        if (history) {
            // The previous (jittered) projection the previous rays were traced with.
            const FrameUniforms& hu = *ctx.history_uniforms;
            prev_proj = glm::vec4(hu.proj[0][0], hu.proj[1][1], hu.proj[2][0], hu.proj[2][1]);
        }
        glUniform1i(glGetUniformLocation(prog, "u_has_previous_rays"), history ? 1 : 0);
        // V_curr V_prev^-1 and its inverse in double precision (identities for a static camera).
        (history ? ReprojectPass::history_camera(ctx) : HistoryCamera{}).set(prog);
        glUniform4fv(glGetUniformLocation(prog, "u_previous_proj"), 1, glm::value_ptr(prev_proj));
    }
    bind_ray_inputs(ctx, prog, units, "passes/resolve.comp");
    if (list) {
        // The classify pass (run before, build_chain) wrote the list and its dispatch arguments;
        // an empty list is a dispatch of 0 groups.
        ctx.buffers.get("resolve_list").bind();
        glDispatchComputeIndirect(0);
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                        GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
        return;
    }
    // The group size is the shader's choice (its shared-memory tile): read it from the program.
    GLint group[3] = {16, 16, 1};
    glGetProgramiv(prog, GL_COMPUTE_WORK_GROUP_SIZE, group);
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, group[0], group[1]);
}

SSR_REGISTER_PASS(ResolvePass());

}  // namespace ssr
