#include "passes/cone_trace.h"

#include "render/pass_registry.h"

#include "passes/compute.h"
#include "passes/specular_occlusion.h"

namespace ssr {

std::vector<std::string> ConeTracePass::inputs(const RenderSettings& s, const FrameFacts&) const {
    std::vector<std::string> in{"rays.hit", "rays.sample", "rays.direction", "lit", "linear_depth", "gbuffer.albedo",
                "gbuffer.normal", "gbuffer.material", "lit_preconvolved", "visibility", "hiz"};
    if (SpecularOcclusionPass::enabled(s)) in.push_back("rays.radiance");
    return in;
}

void ConeTracePass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    // Unresolved rays bring the specular_occlusion pass's estimate (lib/glossy_common.glsl).
    const bool occlusion = SpecularOcclusionPass::enabled(ctx.settings);
    Defines d = ctx.defines;
    d["SPECULAR_OCCLUSION"] = occlusion ? "1" : "0";
    const NamedUnits units{inputs(ctx.settings, ctx.facts), {{"reflection", GL_WRITE_ONLY}}};
    units.add_unit_defines(d);
    glUseProgram(ctx.shaders.program({"passes/cone_trace.comp"}, d));
    units.bind_by_name(r);
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 8, 8);
}

SSR_REGISTER_PASS(ConeTracePass());

}  // namespace ssr
