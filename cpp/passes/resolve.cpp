#include "passes/resolve.h"

#include "passes/compute.h"

namespace ssr {

void ResolvePass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    glUseProgram(ctx.shaders.program({"passes/resolve.comp"}, ctx.defines));
    const char* inputs[] = {"rays.hit", "rays.sample", "rays.direction", "lit", "linear_depth",
                            "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"};
    for (GLuint unit = 0; unit < 8; ++unit) glBindTextureUnit(unit, r.get(inputs[unit]).id());
    bind_image_layered(0, r.get("reflection"), GL_WRITE_ONLY);
    dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 16, 16);
}

}  // namespace ssr
