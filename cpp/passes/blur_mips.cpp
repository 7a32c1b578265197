#include "passes/blur_mips.h"

#include "passes/compute.h"

namespace ssr {

void BlurMipsPass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    glUseProgram(ctx.shaders.program({"passes/blur_mips.comp"}, ctx.defines));
    bind_inputs_in_order(r, inputs());
    bind_image_layered(0, r.get("reflection"), GL_WRITE_ONLY);
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 8, 8);
}

}  // namespace ssr
