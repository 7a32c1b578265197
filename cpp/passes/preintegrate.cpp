#include "passes/preintegrate.h"

#include "render/pass_registry.h"

#include <algorithm>

#include "passes/compute.h"

namespace ssr {

void PreintegratePass::execute(FrameContext& ctx) {
    Texture& vis = ctx.resources.get("visibility");
    Texture& hiz = ctx.resources.get("hiz");
    // Layers empty everywhere have visibility 0 at every level (the shader's value).
    const int layers = ctx.layers_in_use();
    const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    clear_layers(ctx, vis, layers, zero);
    // The cone tracer reads it trilinearly (seed 002, 4.4.5).
    vis.set_filter(GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR);

    if (layers == 0) return;

    Defines level0 = ctx.defines;
    level0["LEVEL0"] = "1";
    glUseProgram(ctx.shaders.program({"passes/preintegrate.comp"}, level0));
    glBindTextureUnit(1, ctx.resources.get("gbuffer.material").id());
    bind_image_layered(0, vis, GL_WRITE_ONLY, 0);
    dispatch_2d(vis.width(), vis.height(), layers, 8, 8);

    Defines coarser = ctx.defines;
    coarser["LEVEL0"] = "0";
    glUseProgram(ctx.shaders.program({"passes/preintegrate.comp"}, coarser));
    for (int level = 1; level < vis.levels(); ++level) {
        bind_image_layered(0, vis, GL_WRITE_ONLY, level);
        bind_image_layered(1, vis, GL_READ_ONLY, level - 1);
        bind_image_layered(2, hiz, GL_READ_ONLY, level - 1);
        bind_image_layered(3, hiz, GL_READ_ONLY, level);
        dispatch_2d(std::max(vis.width() >> level, 1), std::max(vis.height() >> level, 1), layers, 8, 8);
    }
}

SSR_REGISTER_PASS(PreintegratePass());

}  // namespace ssr
