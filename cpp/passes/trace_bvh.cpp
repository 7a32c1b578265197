#include "passes/trace_bvh.h"

#include "passes/compute.h"
#include "render/gpu_scene.h"

namespace ssr {

std::vector<std::string> TraceBvhPass::inputs() const {
    std::vector<std::string> in = {"linear_depth", "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"};
    if (fallback_) {
        in.push_back("rays.hit");
        in.push_back("rays.sample");
        in.push_back("rays.direction");
    }
    if (shadows_) in.push_back("shadow_map");
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
    d["SHADOWS"] = shadows_ ? "1" : "0";
    d["CONFIDENCE"] = fallback_ && ctx.settings.fallback_confidence ? "1" : "0";
    const GLuint prog = ctx.shaders.program({"passes/trace_bvh.comp"}, d);
    // The BVH and the scene's vertex and image buffers (built on first use, then kept with the
    // scene's GPU copy; binding them does not change what the scene holds).
    const_cast<GpuScene&>(ctx.gpu_scene).bind_ray_tracing(ctx.scene);
    glUseProgram(prog);
    glBindTextureUnit(0, r.get("linear_depth").id());
    glBindTextureUnit(1, r.get("gbuffer.albedo").id());
    glBindTextureUnit(2, r.get("gbuffer.normal").id());
    glBindTextureUnit(3, r.get("gbuffer.material").id());
    if (shadows_) glBindTextureUnit(4, r.get("shadow_map").id());
    if (fallback_) {
        bind_image_layered(4, r.get("rays.hit"), GL_READ_WRITE);
        glBindTextureUnit(6, r.get("rays.sample").id());
        glBindTextureUnit(7, r.get("rays.direction").id());
    } else {
        bind_image_layered(0, r.get("rays.hit"), GL_WRITE_ONLY);
        bind_image_layered(1, r.get("rays.sample"), GL_WRITE_ONLY);
        bind_image_layered(2, r.get("rays.direction"), GL_READ_WRITE);
    }
    bind_image_layered(3, r.get("rays.radiance"), GL_WRITE_ONLY);
    const RenderSettings& s = ctx.settings;
    dispatch_2d(s.trace_width(), s.trace_height(), s.traced_rays(), 8, 8);
}

}  // namespace ssr
