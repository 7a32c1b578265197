#include "passes/reference.h"

#include <algorithm>

#include "passes/compute.h"

namespace ssr {

namespace {
// Rays per dispatch: about a million, so no single dispatch runs for long on any device.
constexpr long long kRaysPerDispatch = 1 << 20;
}  // namespace

std::vector<std::string> ReferencePass::inputs() const {
    std::vector<std::string> in = {"linear_depth", "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"};
    if (per_ray_) {
        in.push_back("rays.direction");
        in.push_back("rays.sample");
    }
    if (shadows_ && !traced_shadows_) in.push_back("shadow_map");
    return in;
}

std::vector<ResourceDesc> ReferencePass::outputs(const RenderSettings& s) const {
    if (per_ray_) {
        const int w = s.trace_width(), h = s.trace_height(), r = s.traced_rays();
        return {{"reference.hit", GL_RGBA32F, w, h, r, 1},
                {"reference.position", GL_RGBA32F, w, h, r, 1},
                {"reference.radiance", GL_RGBA32F, w, h, r, 1}};
    }
    return {{"reference.accum", GL_RGBA32F, s.width, s.height, 0, 1},
            {"reference.reflection", GL_RGBA32F, s.width, s.height, 0, 1},
            {"reference.direct", GL_RGBA32F, s.width, s.height, 1, 1}};
}

GLuint ReferencePass::program(FrameContext& ctx) const {
    Defines d = ctx.defines;
    d["MODE"] = per_ray_ ? "0" : "1";
    d["SHADOWS"] = shadows_ && !traced_shadows_ ? "1" : "0";
    d["TRACED_SHADOWS"] = shadows_ && traced_shadows_ ? "1" : "0";
    return ctx.shaders.program({"passes/reference.comp"}, d);
}

void ReferencePass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    const GLuint prog = program(ctx);
    glUseProgram(prog);
    glBindTextureUnit(0, r.get("linear_depth").id());
    glBindTextureUnit(1, r.get("gbuffer.albedo").id());
    glBindTextureUnit(2, r.get("gbuffer.normal").id());
    glBindTextureUnit(3, r.get("gbuffer.material").id());
    if (shadows_ && !traced_shadows_) glBindTextureUnit(4, r.get("shadow_map").id());
    const GLint loc_first = glGetUniformLocation(prog, "u_first_ray");
    const GLint loc_count = glGetUniformLocation(prog, "u_ray_count");
    const GLint loc_last = glGetUniformLocation(prog, "u_last");
    glUniform1i(glGetUniformLocation(prog, "u_viewer"), viewer_is_ray_ ? 1 : 0);
    const RenderSettings& s = ctx.settings;
    if (per_ray_) {
        glBindTextureUnit(5, r.get("rays.direction").id());
        glBindTextureUnit(6, r.get("rays.sample").id());
        bind_image_layered(0, r.get("reference.hit"), GL_WRITE_ONLY);
        bind_image_layered(1, r.get("reference.position"), GL_WRITE_ONLY);
        bind_image_layered(2, r.get("reference.radiance"), GL_WRITE_ONLY);
        const long long per_ray = (long long)s.trace_width() * s.trace_height();
        const int chunk = int(std::max(1LL, std::min<long long>(s.traced_rays(), kRaysPerDispatch / per_ray)));
        for (int first = 0; first < s.traced_rays(); first += chunk) {
            const int count = std::min(chunk, s.traced_rays() - first);
            glUniform1i(loc_first, first);
            glUniform1i(loc_count, count);
            glUniform1i(loc_last, first + count >= s.traced_rays());
            dispatch_2d(s.trace_width(), s.trace_height(), count, 8, 8);
        }
    } else {
        bind_image_layered(0, r.get("reference.accum"), GL_READ_WRITE);
        bind_image_layered(1, r.get("reference.reflection"), GL_WRITE_ONLY);
        bind_image_layered(2, r.get("reference.direct"), GL_WRITE_ONLY);
        const long long per_ray = (long long)s.width * s.height;
        const int chunk = int(std::max(1LL, std::min<long long>(rays_, kRaysPerDispatch / per_ray)));
        for (int first = 0; first < rays_; first += chunk) {
            const int count = std::min(chunk, rays_ - first);
            glUniform1i(loc_first, first);
            glUniform1i(loc_count, count);
            glUniform1i(loc_last, first + count >= rays_);
            dispatch_2d(s.width, s.height, 1, 8, 8);
        }
    }
}

}  // namespace ssr
