#include "passes/specular_occlusion.h"

#include "render/pass_registry.h"

#include "core/gpu_timer.h"
#include "passes/compute.h"

namespace ssr {

bool SpecularOcclusionPass::enabled(const RenderSettings& s) {
    return s.specular_occlusion != SpecularOcclusion::Off && s.method != TraceMethod::Bvh &&
           s.method != TraceMethod::Off && s.fallback == Fallback::Environment;
}

void SpecularOcclusionPass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    const RenderSettings& s = ctx.settings;
    Defines d = ctx.defines;
    d["METHOD"] = s.specular_occlusion == SpecularOcclusion::Horizon ? "1" : "2";
    // cone and blur_mips trace one mirror ray that stands for the whole lobe.
    d["LOBE"] = s.glossy == Glossy::Stochastic ? "0" : "1";
    // The float inputs by imageLoad on the CPU device, image units 2-8.
    auto bind_inputs = [&]() {
        bind_inputs_in_order(r, inputs(ctx.settings, ctx.facts));
        if (ctx.fetch_by_image())
            bind_input_images(r, 2, {"linear_depth", "gbuffer.normal", "lit", "rays.hit", "rays.sample", "rays.direction"});
    };
    const bool exit = s.specular_occlusion == SpecularOcclusion::Exit;
    if (exit) {
        // The enclosure cells: each cell's farthest surface (or open background), then the
        // same over it and its 8 neighbours. Timed as a part of the pass.
        GpuScope t(ctx.timer, name() + ".cells");
        const Texture& cells = r.get("occlusion_cells");
        Defines d0 = d;
        d0["STAGE"] = "0";
        glUseProgram(ctx.shaders.program({"passes/specular_occlusion.comp"}, d0));
        bind_inputs();
        bind_image_layered(1, cells, GL_WRITE_ONLY);
        dispatch_2d(cells.width() * 8, cells.height() * 8, 1, 8, 8);  // a work group of 8x8 per cell
        d0["STAGE"] = "1";
        glUseProgram(ctx.shaders.program({"passes/specular_occlusion.comp"}, d0));
        bind_image_layered(0, r.get("occlusion_enclosure"), GL_WRITE_ONLY);
        bind_image_layered(1, cells, GL_READ_ONLY);
        dispatch_2d(cells.width(), cells.height(), 1, 8, 8);
    }
    // Frame.stats counts this run's rays once, whichever run of the chain this is (a variant's
    // first render runs it twice, render_loop.cpp). The counters are set to zero by a dispatch
    // (stage 3), ordered after the previous run's atomics on the device's own timeline. With a
    // buffer update from the host as the reset, an H100 reported unresolved_rays twice the rays the
    // frame marked in rays.radiance: both runs' counts.
    if (!counters_) counters_ = Buffer::create(2 * sizeof(uint32_t));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kCountersBinding, counters_.id());
    Defines d3 = ctx.defines;
    d3["STAGE"] = "3";
    glUseProgram(ctx.shaders.program({"passes/specular_occlusion.comp"}, d3));
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);  // the previous run's atomics, before the reset
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);  // the reset, before this run's atomics
    d["STAGE"] = "2";
    glUseProgram(ctx.shaders.program({"passes/specular_occlusion.comp"}, d));
    bind_inputs();
    if (exit) {
        glBindTextureUnit(8, r.get("occlusion_enclosure").id());
        if (ctx.fetch_by_image()) bind_image_layered(8, r.get("occlusion_enclosure"), GL_READ_ONLY);
    }
    bind_image_layered(0, r.get("rays.radiance"), GL_WRITE_ONLY);
    glUniform1i(0, s.traced_rays());
    dispatch_2d(s.trace_width(), s.trace_height(), 1, 8, 8);
}

std::map<std::string, double> SpecularOcclusionPass::counters() const {
    uint32_t c[2] = {0, 0};
    if (!counters_) return {};
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(counters_.id(), 0, sizeof(c), c);
    return {{"unresolved_rays", double(c[0])}, {"occluded_misses", double(c[1])}};
}

SSR_REGISTER_PASS(SpecularOcclusionPass());

}  // namespace ssr
