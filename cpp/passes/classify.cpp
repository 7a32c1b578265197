#include "passes/classify.h"

#include <cstdint>

#include "passes/compute.h"

namespace ssr {

namespace {
constexpr size_t kHeaderUints = 8;  // shaders/lib/ray_list.glsl
}

void ClassifyPass::bind() const {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBinding, list_.id());
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, list_.id());
}

void ClassifyPass::reset_list(int w, int h, int rays, bool per_ray) {
    const size_t entries = size_t(w) * size_t(h) * (per_ray ? 2 * size_t(rays) : 1);
    const size_t bytes = (kHeaderUints + entries) * sizeof(uint32_t);
    if (list_.size() < bytes) list_ = Buffer::create(bytes);
    per_ray_ = per_ray;
    // A fresh header each frame: no groups, no rows of groups yet, a group layer per ray (one
    // layer when every entry is a ray).
    const uint32_t header[kHeaderUints] = {0, 0, per_ray ? 1u : uint32_t(rays), 0, 0, 0, 0, 0};
    list_.upload(header, sizeof(header));
}

void ClassifyPass::execute(FrameContext& ctx) {
    const RenderSettings& s = ctx.settings;
    const int w = s.trace_width(), h = s.trace_height();
    reset_list(w, h, s.traced_rays(), per_ray(s));

    Defines d = ctx.defines;
    d["RAY_LIST_PER_RAY"] = per_ray(s) ? "1" : "0";
    d["CLASSIFY_FACING"] = std::to_string(s.classify_facing);
    d["ADAPTIVE_RAYS"] = s.adaptive_rays ? "1" : "0";
    const GLuint prog = ctx.shaders.program({"passes/classify.comp"}, d);
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_rays"), s.traced_rays());
    auto& r = ctx.resources;
    bind_ray_generation_io(r);
    bind();
    dispatch_2d(w, h, 1, 8, 8);
    glMemoryBarrier(GL_COMMAND_BARRIER_BIT);  // the trace pass's indirect arguments
}

std::map<std::string, double> ClassifyPass::counters() const {
    uint32_t header[kHeaderUints] = {};
    if (!list_) return {};
    glGetNamedBufferSubData(list_.id(), 0, sizeof(header), header);
    return {{"pixels_classified", double(header[6])},
            {"pixels_traced", double(per_ray_ ? header[7] : header[3])},
            {"trace_groups", double(header[0]) * header[1] * header[2]},
            {"rays_traced", double(header[4])},
            {"depth_fetches", double(header[5])}};
}

}  // namespace ssr
