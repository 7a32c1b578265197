#include "passes/trace_pass.h"

#include "core/errors.h"
#include "passes/compute.h"
#include "render/ssr_uniforms.h"

namespace ssr {

ResourceDesc TracePass::ray_texture(const std::string& name, const RenderSettings& s) {
    using D = ChannelDecode;
    std::vector<ChannelDesc> c;
    if (name == "rays.hit")
        c = {{"rays", "hit_position", 0, 2, D::WindowPoint,
              "where the ray hit, in pixels of the frame (column, row from the top); meaningless for misses"},
             {"rays", "hit_layer", 2, 1, D::Integer, "G-buffer layer hit, 1-based; 0 = miss (as the thesis stores it)"},
             {"rays", "fade", 3, 1, D::Value, "1 = hit kept, 0 = replaced by the environment"}};
    else if (name == "rays.sample")
        c = {{"rays", "weight", 0, 1, D::Value, "f_r cos / pdf without Fresnel; 0 for no ray or an invalid sample"},
             {"rays", "pdf", 1, 1, D::Value, "solid-angle pdf of the direction; 0 for mirror (Dirac) directions"},
             {"rays", "steps", 2, 1, D::Value, "depth fetches the ray spent"},
             {"rays", "traced_ray", 3, 1, D::Flag, "the slot holds a traced ray"}};
    else if (name == "rays.direction")
        c = {{"rays", "direction", 0, 3, D::Value, "view-space unit direction (0 where the pixel traces no ray)"}};
    return ResourceDesc{name, GL_RGBA32F, s.trace_width(), s.trace_height(), s.traced_rays(), 1}.with(std::move(c));
}

void TracePass::run(FrameContext& ctx, const std::string& stage, const std::function<void(GLuint)>& setup,
                    const NamedUnits& own) {
    auto& r = ctx.resources;
    const bool skip = ctx.settings.skip || extra_;
    Defines d = ctx.defines;
    d["RAY_LIST"] = skip ? "1" : "0";
    d["ADAPTIVE_RAYS"] = ctx.settings.adaptive_rays && !extra_ ? "1" : "0";
    d["EXTRA_RAYS"] = extra_ ? "1" : "0";
    d["RAY_LIST_PER_RAY"] = !extra_ && ClassifyPass::per_ray(ctx.settings) ? "1" : "0";
    // A variant for one layer in use (the layer walk without its loop; at most two
    // variants, so layers_used changing between frames recompiles nothing more than once).
    d["TRACE_ONE_LAYER"] = ctx.layers_in_use() == 1 ? "1" : "0";
    // The hybrid that keeps only the hits it can vouch for (fallback "bvh" with its confidence
    // test): the march ends where the ray leaves the G-buffer's sight and the BVH retraces it
    // (shaders/lib/screen_sight.glsl). Other fallbacks keep the tracer's own guess.
    d["STOP_UNSEEN"] = ctx.settings.fallback == Fallback::Bvh && ctx.settings.fallback_confidence ? "1" : "0";
    // trace_hiz's level-0 steps before the traversal (seed 002 4.7.1), compiled in only when asked.
    d["HIZ_LINEAR_STEPS"] = ctx.settings.hiz_linear_steps > 0 ? "1" : "0";
    // The sampling method, noise and Hammersley switch compiled in (lib/ray_generation.glsl):
    // llvmpipe runs both sides of a branch, so a run-time choice paid for every kind; the values
    // the settings block holds, from the same function.
    const SsrUniforms su = ssr_uniforms(ctx.settings);
    d["RAY_SAMPLING"] = std::to_string(su.sampling);
    d["RAY_NOISE"] = std::to_string(su.noise);
    d["RAY_HAMMERSLEY"] = std::to_string(su.hammersley);
    // The float inputs by imageLoad on the CPU device (lib/input_fetch.glsl).
    NamedUnits units = ray_generation_units();
    units.fetch(ctx.fetch_by_image(), {"linear_depth", "gbuffer.normal"});
    units.textures.insert(units.textures.end(), own.textures.begin(), own.textures.end());
    units.images.insert(units.images.end(), own.images.begin(), own.images.end());
    units.placed_textures = own.placed_textures;
    units.placed_images = own.placed_images;
    units.own = own.own;
    units.add_unit_defines(d);
    const GLuint prog = ctx.shaders.program({stage}, d);
    glUseProgram(prog);
    // The layer walk stops at the layers in use (a uniform: no recompile per count).
    glUniform1i(glGetUniformLocation(prog, "u_layers_used"), ctx.layers_in_use());
    if (setup) setup(prog);
    units.bind_by_name(r, prog, stage);
    if (skip) {
        // The classify (or variance_rays) pass wrote the list and its dispatch arguments: groups
        // of 64 list entries, a group layer per ray.
        ctx.buffers.get(extra_ ? "extra_ray_list" : "ray_list").bind();
        glDispatchComputeIndirect(0);
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                        GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    } else {
        dispatch_2d(ctx.settings.trace_width(), ctx.settings.trace_height(), ctx.settings.traced_rays(), 8, 8);
    }
}

}  // namespace ssr
