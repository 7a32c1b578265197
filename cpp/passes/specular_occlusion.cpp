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
    const bool exit = s.specular_occlusion == SpecularOcclusion::Exit;
    // Every stage declares the inputs (the float ones by imageLoad on the CPU device); "exit"
    // (METHOD 2) also reads the enclosure cells, which stage 1 writes.
    const std::string shader = "passes/specular_occlusion.comp";
    auto stage_units = [&](int stage) {
        NamedUnits u{inputs(ctx.settings, ctx.facts), {}};
        if (stage == 0) u.images = {{"occlusion_cells", GL_WRITE_ONLY}};
        if (stage == 1) u.images = {{"occlusion_enclosure", GL_WRITE_ONLY}, {"occlusion_cells", GL_READ_ONLY}};
        if (stage == 2) u.images = {{"rays.radiance", GL_WRITE_ONLY}};
        std::vector<std::string> fetched = {"linear_depth", "gbuffer.normal", "lit", "rays.hit", "rays.sample", "rays.direction"};
        if (exit) {
            u.textures.push_back("occlusion_enclosure");
            if (stage != 1) fetched.push_back("occlusion_enclosure");
        }
        u.fetch(ctx.fetch_by_image(), fetched);
        return u;
    };
    auto use = [&](int stage, Defines dd) {
        const NamedUnits u = stage_units(stage);
        dd["STAGE"] = std::to_string(stage);
        u.add_unit_defines(dd);
        const GLuint prog = ctx.shaders.program({shader}, dd);
        glUseProgram(prog);
        u.bind_by_name(r, prog, shader);
    };
    if (exit) {
        // The enclosure cells: each cell's farthest surface (or open background), then the
        // same over it and its 8 neighbours. Timed as a part of the pass.
        GpuScope t(ctx.timer, name() + ".cells");
        const Texture& cells = r.get("occlusion_cells");
        use(0, d);
        dispatch_2d(cells.width() * 8, cells.height() * 8, 1, 8, 8);  // a work group of 8x8 per cell
        use(1, d);
        dispatch_2d(cells.width(), cells.height(), 1, 8, 8);
    }
    // Frame.stats counts this run's rays once, whichever run of the chain this is (a variant's
    // first render runs it twice, render_loop.cpp). The counters are set to zero by a dispatch
    // (stage 3), ordered after the previous run's atomics on the device's own timeline. With a
    // buffer update from the host as the reset, an H100 reported unresolved_rays twice the rays the
    // frame marked in rays.radiance: both runs' counts.
    if (!counters_) counters_ = Buffer::create(2 * sizeof(uint32_t));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kCountersBinding, counters_.id());
    use(3, d);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);  // the previous run's atomics, before the reset
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);  // the reset, before this run's atomics
    use(2, d);
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
