#include "passes/resolve_fetch.h"

#include "render/pass_registry.h"

#include "passes/compute.h"
#include "passes/resolve.h"

namespace ssr {

void ResolveFetchPass::execute(FrameContext& ctx) {
    const GLuint prog = ctx.shaders.program({"passes/resolve_fetch.comp"}, ResolvePass::ray_defines(ctx));
    glUseProgram(prog);
    ResolvePass::bind_ray_inputs(ctx, prog);
    bind_image_layered(8, ctx.resources.get("resolve.ray_color"), GL_WRITE_ONLY);
    bind_image_layered(9, ctx.resources.get("resolve.ray_target"), GL_WRITE_ONLY);
    const RenderSettings& s = ctx.settings;
    dispatch_2d(s.trace_width(), s.trace_height(), s.traced_rays(), 8, 8);
}

SSR_REGISTER_PASS(ResolveFetchPass());

}  // namespace ssr
