#include "passes/variance_rays.h"

#include "render/pass_registry.h"

#include <cstdint>

#include "passes/compute.h"

namespace ssr {

void VarianceRaysPass::execute(FrameContext& ctx) {
    const RenderSettings& s = ctx.settings;
    const int w = s.trace_width(), h = s.trace_height();
    reset_list(w, h, s.traced_rays());
    Defines d = ctx.defines;
    d["ADAPTIVE_RAYS"] = "1";
    const NamedUnits units{inputs(ctx.settings, ctx.facts), {{"variance", GL_WRITE_ONLY}}};
    units.add_unit_defines(d);
    const GLuint prog = ctx.shaders.program({"passes/variance_rays.comp"}, d);
    glUseProgram(prog);
    glUniform1f(glGetUniformLocation(prog, "u_threshold"), s.variance_threshold);
    auto& r = ctx.resources;
    units.bind_by_name(r);
    bind_list();
    dispatch_2d(w, h, 1, 8, 8);
    glMemoryBarrier(GL_COMMAND_BARRIER_BIT);  // the second trace's indirect arguments
    publish_list(ctx, "extra_ray_list");
}

std::map<std::string, double> VarianceRaysPass::extra_counters() const {
    uint32_t header[8] = {};  // shaders/lib/ray_list.glsl
    if (!list_) return {};
    // GL makes the shaders' atomics visible to glGetBufferSubData only after this barrier
    // (llvmpipe finishes every dispatch first; a GPU need not).
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(list_.id(), 0, sizeof(header), header);
    return {{"variance_pixels", double(header[3])},
            {"extra_rays", double(header[4])},
            {"extra_depth_fetches", double(header[5])}};
}

SSR_REGISTER_PASS(VarianceRaysPass());

}  // namespace ssr
