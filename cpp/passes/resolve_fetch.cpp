#include "passes/resolve_fetch.h"

#include "render/pass_registry.h"

#include "passes/compute.h"
#include "passes/resolve.h"

namespace ssr {

void ResolveFetchPass::execute(FrameContext& ctx) {
    NamedUnits units = ResolvePass::ray_units(ctx);
    units.images.insert(units.images.end(), {{"resolve.ray_color", GL_WRITE_ONLY}, {"resolve.ray_target", GL_WRITE_ONLY}});
    Defines d = ResolvePass::ray_defines(ctx);
    units.add_unit_defines(d);
    const GLuint prog = ctx.shaders.program({"passes/resolve_fetch.comp"}, d);
    glUseProgram(prog);
    ResolvePass::bind_ray_inputs(ctx, prog, units, "passes/resolve_fetch.comp");
    const RenderSettings& s = ctx.settings;
    dispatch_2d(s.trace_width(), s.trace_height(), s.traced_rays(), 8, 8);
}

SSR_REGISTER_PASS(ResolveFetchPass());

}  // namespace ssr
