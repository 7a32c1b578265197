#include "passes/cone_trace.h"

#include "render/pass_registry.h"

#include "passes/compute.h"
#include "passes/specular_occlusion.h"

namespace ssr {

std::vector<std::string> ConeTracePass::inputs(const RenderSettings& s, const FrameFacts&) const {
    std::vector<std::string> in = in_order();
    if (SpecularOcclusionPass::enabled(s)) in.push_back("rays.radiance");
    return in;
}

void ConeTracePass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    // Unresolved rays bring the specular_occlusion pass's estimate (lib/glossy_common.glsl).
    const bool occlusion = SpecularOcclusionPass::enabled(ctx.settings);
    Defines d = ctx.defines;
    d["SPECULAR_OCCLUSION"] = occlusion ? "1" : "0";
    glUseProgram(ctx.shaders.program({"passes/cone_trace.comp"}, d));
    bind_inputs_in_order(r, in_order());
    if (occlusion) glBindTextureUnit(12, r.get("rays.radiance").id());
    bind_image_layered(0, r.get("reflection"), GL_WRITE_ONLY);
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 8, 8);
}

SSR_REGISTER_PASS(ConeTracePass());

}  // namespace ssr
