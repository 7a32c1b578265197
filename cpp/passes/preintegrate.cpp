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

    // By name: "visibility.level" the level written, "visibility.finer" the one below, and the
    // Hi-Z's levels "hiz.finer" and "hiz.coarse" (mip levels of visibility and hiz).
    const std::string shader = "passes/preintegrate.comp";
    NamedUnits u0{{"gbuffer.material"}, {{"visibility.level", GL_WRITE_ONLY}}};
    u0.own = {{"visibility.level", &vis}};
    NamedUnits u1{{},
                  {{"visibility.level", GL_WRITE_ONLY}, {"visibility.finer", GL_READ_ONLY}, {"hiz.finer", GL_READ_ONLY},
                   {"hiz.coarse", GL_READ_ONLY}}};
    Defines level0 = ctx.defines;
    level0["LEVEL0"] = "1";
    u0.add_unit_defines(level0);
    const GLuint prog0 = ctx.shaders.program({shader}, level0);
    glUseProgram(prog0);
    u0.bind_by_name(ctx.resources, prog0, shader);
    dispatch_2d(vis.width(), vis.height(), layers, 8, 8);

    Defines coarser = ctx.defines;
    coarser["LEVEL0"] = "0";
    u1.add_unit_defines(coarser);
    const GLuint prog1 = ctx.shaders.program({shader}, coarser);
    glUseProgram(prog1);
    u1.check(prog1, shader);
    for (int level = 1; level < vis.levels(); ++level) {
        bind_image_layered(u1.image_unit("visibility.level"), vis, GL_WRITE_ONLY, level);
        bind_image_layered(u1.image_unit("visibility.finer"), vis, GL_READ_ONLY, level - 1);
        bind_image_layered(u1.image_unit("hiz.finer"), hiz, GL_READ_ONLY, level - 1);
        bind_image_layered(u1.image_unit("hiz.coarse"), hiz, GL_READ_ONLY, level);
        dispatch_2d(std::max(vis.width() >> level, 1), std::max(vis.height() >> level, 1), layers, 8, 8);
    }
}

SSR_REGISTER_PASS(PreintegratePass());

}  // namespace ssr
