#include "passes/trace_bvh.h"

#include "render/pass_registry.h"

#include "passes/compute.h"
#include "passes/depth_peel.h"
#include "passes/shadow_map.h"
#include "render/gpu_scene.h"

namespace ssr {

std::vector<std::string> TraceBvhPass::inputs(const RenderSettings& s, const FrameFacts& f) const {
    std::vector<std::string> in = {"linear_depth", "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"};
    if (fallback_) {
        in.push_back("rays.sample");
        in.push_back("rays.direction");
    }
    if (s.bvh_shadows != BvhShadows::Traced)
        for (const auto& t : ShadowMapPass::reads(f)) in.push_back(t);
    // The fallback shades screen-space hits from the G-buffer (lib/gbuffer_emission.glsl).
    if (fallback_ && f.emission_texture) in.push_back("gbuffer.emission");
    if (fallback_ && f.specular_texture) in.push_back("gbuffer.specular");  // lib/gbuffer_specular.glsl
    return in;
}

std::vector<ResourceDesc> TraceBvhPass::outputs(const RenderSettings& s) const {
    const int w = s.trace_width(), h = s.trace_height(), r = s.traced_rays();
    std::vector<ResourceDesc> out;
    if (!fallback_) out = TracePass::outputs(s);
    out.push_back({"rays.radiance", GL_RGBA32F, w, h, r, 1});
    return out;
}

void TraceBvhPass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    Defines d = ctx.defines;
    d["FALLBACK"] = fallback_ ? "1" : "0";
    d["STAGE"] = "0";
    // bvh_shadows: the frame's shadow map as the lit G-buffer has it, or the
    // reference's traced shadow ray (lib/trace_shade.glsl), exact where the map blurs.
    const bool traced = ctx.settings.bvh_shadows == BvhShadows::Traced;
    d["SHADOWS"] = ctx.facts.shadows && !traced ? "1" : "0";
    d["TRACED_SHADOWS"] = ctx.facts.shadows && traced ? "1" : "0";
    ShadowMapPass::add_defines(d, ctx.facts);
    d["CONFIDENCE"] = fallback_ && ctx.settings.fallback_confidence ? "1" : "0";
    if (fallback_ && ctx.facts.emission_texture) d["EMISSION_TEXTURE"] = "1";
    if (fallback_ && ctx.facts.specular_texture) d["SPECULAR_TEXTURE"] = "1";
    // Method "bvh" draws adaptive rays as the screen-space tracers do
    // (lib/ray_generation.glsl's rays_for_roughness); the fallback retraces only the rays the
    // screen-space tracer drew, so it needs no count of its own.
    d["ADAPTIVE_RAYS"] = !fallback_ && ctx.settings.adaptive_rays ? "1" : "0";
    //, skip with method "bvh": the rays to trace (weight > 0) are compacted into the
    // list the fallback uses, so the BVH's SIMD lanes follow the rays drawn. Without it, one
    // invocation per (pixel, ray slot): an adaptive pixel's unused slots and a matte pixel's
    // idle lanes ride along with their neighbours' traversals. The images are the same.
    const bool compact = !fallback_ && ctx.settings.skip;
    d["COMPACT"] = compact ? "1" : "0";
    // The fallback reads the screen-space tracer's rays and completes rays.hit; the tracer of
    // every ray writes them (lib/trace_common.glsl's outputs, rays.direction readable).
    NamedUnits units{{"linear_depth", "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"}, {}};
    if (!traced)
        for (const auto& m : ShadowMapPass::reads(ctx.facts)) units.textures.push_back(m);
    if (fallback_ && ctx.facts.emission_texture) units.textures.push_back("gbuffer.emission");
    if (fallback_ && ctx.facts.specular_texture) units.textures.push_back("gbuffer.specular");
    if (fallback_) {
        units.textures.insert(units.textures.end(), {"rays.sample", "rays.direction"});
        units.images = {{"rays.hit", GL_READ_WRITE}};
    } else {
        units.images = {{"rays.hit", GL_WRITE_ONLY}, {"rays.sample", GL_WRITE_ONLY}, {"rays.direction", GL_READ_WRITE}};
    }
    units.images.emplace_back("rays.radiance", GL_WRITE_ONLY);
    units.add_unit_defines(d);
    const GLuint prog = ctx.shaders.program({"passes/trace_bvh.comp"}, d);
    const RenderSettings& s = ctx.settings;
    // The BVH and the scene's vertex and image buffers (built on first use, then kept with the
    // scene's GPU copy; binding them does not change what the scene holds).
    const_cast<GpuScene&>(ctx.gpu_scene).bind_ray_tracing(ctx.scene);
    glUseProgram(prog);
    units.bind_by_name(r, prog, "passes/trace_bvh.comp");
    if (!fallback_ && !compact) {
        dispatch_2d(s.trace_width(), s.trace_height(), s.traced_rays(), 8, 8);
        return;
    }
    // The fallback: select the rays to retrace into a compacted list (stage 0), size the
    // indirect dispatch from its count on the GPU (stage 1), trace the list (stage 2). Compact
    // method "bvh": stage 0 draws every ray and lists those with a weight.
    const size_t rays = size_t(s.trace_width()) * size_t(s.trace_height()) * size_t(s.traced_rays());
    if (list_.size() < rays * 16) list_ = Buffer::create(rays * 16);
    if (!count_) count_ = Buffer::create(16);
    const GLuint zero[4] = {0, 0, 0, 0};
    count_.upload(zero, sizeof(zero));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRetraceListBinding, list_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRetraceCountBinding, count_.id());
    // Compact method "bvh": stage 0 is one invocation per trace pixel for all its ray slots.
    dispatch_2d(s.trace_width(), s.trace_height(), compact ? 1 : s.traced_rays(), 8, 8);
    for (int stage = 1; stage <= 2; ++stage) {
        Defines ds = d;
        ds["STAGE"] = std::to_string(stage);
        glUseProgram(ctx.shaders.program({"passes/trace_bvh.comp"}, ds));
        if (stage == 1) {
            glDispatchCompute(1, 1, 1);
            glMemoryBarrier(GL_COMMAND_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        } else {
            glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, count_.id());
            glDispatchComputeIndirect(4);  // groups[3] follows the count
            glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
            glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                            GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
        }
    }
}

SSR_REGISTER_PASS(TraceBvhPass(false));
SSR_REGISTER_PASS(TraceBvhPass(true));

}  // namespace ssr
