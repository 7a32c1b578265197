#include "passes/specular_occlusion.h"

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
    if (s.specular_occlusion == SpecularOcclusion::Exit) {
        // Stage 0: the enclosure cells (the farthest surface of each cell, or open background).
        Defines dc = d;
        dc["STAGE"] = "0";
        glUseProgram(ctx.shaders.program({"passes/specular_occlusion.comp"}, dc));
        bind_inputs_in_order(r, inputs());
        bind_image_layered(1, r.get("occlusion_cells"), GL_WRITE_ONLY);
        const Texture& cells = r.get("occlusion_cells");
        dispatch_2d(cells.width(), cells.height(), 1, 8, 8);
    }
    d["STAGE"] = "1";
    glUseProgram(ctx.shaders.program({"passes/specular_occlusion.comp"}, d));
    if (s.specular_occlusion == SpecularOcclusion::Exit) glBindTextureUnit(8, r.get("occlusion_cells").id());
    const uint32_t zero[2] = {0, 0};
    if (!counters_) counters_ = Buffer::create(sizeof(zero));
    counters_.upload(zero, sizeof(zero));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 14, counters_.id());
    bind_inputs_in_order(r, inputs());
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

}  // namespace ssr
