#include "passes/hiz_build.h"

#include "render/pass_registry.h"

#include "passes/compute.h"

namespace ssr {

void HizBuildPass::execute(FrameContext& ctx) {
    Texture& hiz = ctx.resources.get("hiz");
    // Only the layers that hold a surface somewhere; the others read as empty
    // (+inf, -inf) cells at every level, what the shader writes for an uncovered pixel.
    const int layers = ctx.layers_in_use();
    const float empty[2] = {1e30f, -1e30f};  // EMPTY of hiz_build.comp
    clear_layers(ctx, hiz, layers, empty);
    layers_built_ = layers;
    if (layers == 0) return;

    // The tracer's atlas, written by the same dispatches, only where the Hi-Z
    // tracer will read it (hiz_build also serves cone tracing).
    const bool atlas = ctx.settings.method == TraceMethod::Hiz;
    // By name: "hiz.level" the level written, "hiz.finer" the one below it (mip levels of hiz).
    const std::string shader = "passes/hiz_build.comp";
    NamedUnits u0{{"gbuffer.depth", "gbuffer.material"}, {{"hiz.level", GL_WRITE_ONLY}}};
    NamedUnits u1{{}, {{"hiz.level", GL_WRITE_ONLY}, {"hiz.finer", GL_READ_ONLY}}};
    u0.own = {{"hiz.level", &hiz}};
    u1.own = {{"hiz.level", &hiz}, {"hiz.finer", &hiz}};
    if (atlas) {
        u0.images.emplace_back("hiz_trace", GL_WRITE_ONLY);
        u1.images.emplace_back("hiz_trace", GL_WRITE_ONLY);
    }
    if (sight(ctx.settings)) {
        // The sight map's neighbourhoods: view depths, the far plane where a layer is empty.
        u0.textures.push_back("linear_depth");
        u0.fetch(ctx.fetch_by_image(), {"linear_depth"});
    }

    // The sight map of the hybrid's Hi-Z walk (shaders/lib/screen_sight.glsl), and the coarser
    // levels' min built from it.
    const char* sight_map = sight(ctx.settings) ? "1" : "0";
    Defines level0 = ctx.defines;
    level0["HIZ_LEVEL0"] = "1";
    level0["HIZ_TRACE_ATLAS"] = atlas ? "1" : "0";
    level0["HIZ_SIGHT"] = sight_map;
    u0.add_unit_defines(level0);
    GLuint prog = ctx.shaders.program({shader}, level0);
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_level"), 0);
    u0.bind_by_name(ctx.resources, prog, shader);
    dispatch_2d(hiz.width(), hiz.height(), layers, 8, 8);

    Defines coarser = ctx.defines;
    coarser["HIZ_LEVEL0"] = "0";
    coarser["HIZ_TRACE_ATLAS"] = atlas ? "1" : "0";
    coarser["HIZ_SIGHT"] = sight_map;
    u1.add_unit_defines(coarser);
    prog = ctx.shaders.program({shader}, coarser);
    glUseProgram(prog);
    u1.bind_by_name(ctx.resources, prog, shader);
    const GLint level_loc = glGetUniformLocation(prog, "u_level");
    for (int level = 1; level < hiz.levels(); ++level) {
        glUniform1i(level_loc, level);
        bind_image_layered(u1.image_unit("hiz.level"), hiz, GL_WRITE_ONLY, level);
        bind_image_layered(u1.image_unit("hiz.finer"), hiz, GL_READ_ONLY, level - 1);
        dispatch_2d(std::max(hiz.width() >> level, 1), std::max(hiz.height() >> level, 1), layers, 8, 8);
    }
}

SSR_REGISTER_PASS(HizBuildPass());

}  // namespace ssr
