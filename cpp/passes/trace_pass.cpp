#include "passes/trace_pass.h"

#include "passes/compute.h"

namespace ssr {

void TracePass::run(FrameContext& ctx, GLuint program) {
    auto& r = ctx.resources;
    glUseProgram(program);
    glBindTextureUnit(0, r.get("linear_depth").id());
    glBindTextureUnit(1, r.get("gbuffer.albedo").id());
    glBindTextureUnit(2, r.get("gbuffer.normal").id());
    glBindTextureUnit(3, r.get("gbuffer.material").id());
    bind_image_layered(0, r.get("rays.hit"), GL_WRITE_ONLY);
    bind_image_layered(1, r.get("rays.sample"), GL_WRITE_ONLY);
    bind_image_layered(2, r.get("rays.direction"), GL_WRITE_ONLY);
    dispatch_2d(ctx.settings.trace_width(), ctx.settings.trace_height(), ctx.settings.traced_rays(), 8, 8);
}

}  // namespace ssr
