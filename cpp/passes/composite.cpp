#include "passes/composite.h"

#include "passes/compute.h"

namespace ssr {

void CompositePass::execute(FrameContext& ctx) {
    const GLuint prog = ctx.shaders.program({"passes/composite.comp"}, ctx.defines);
    glUseProgram(prog);
    glBindTextureUnit(0, ctx.resources.get("lit").id());
    glBindTextureUnit(1, ctx.resources.get("gbuffer.material").id());
    bind_image_layered(0, ctx.resources.get("color"), GL_WRITE_ONLY);
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 8, 8);
}

}  // namespace ssr
