#include "passes/preconvolve.h"

#include "render/pass_registry.h"

#include <algorithm>

#include "passes/compute.h"

namespace ssr {

void PreconvolvePass::execute(FrameContext& ctx) {
    Texture& pyramid = ctx.resources.get("lit_preconvolved");
    Texture& scratch = ctx.resources.get("preconvolve.scratch");
    // The glossy passes read it trilinearly (seed 002, 4.4.5).
    pyramid.set_filter(GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR);
    // Layers empty everywhere are 0 (no colour, no coverage) at every level.
    const int layers = ctx.layers_in_use();
    const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    clear_layers(ctx, pyramid, layers, zero);
    clear_layers(ctx, scratch, layers, zero);
    if (layers == 0) return;

    // By name: "preconvolve.dst" the level (or scratch) written, "preconvolve.src" the one read.
    const std::string shader = "passes/preconvolve.comp";
    NamedUnits u0{{"lit", "gbuffer.material"}, {{"preconvolve.dst", GL_WRITE_ONLY}}};
    u0.own = {{"preconvolve.dst", &pyramid}};
    NamedUnits u1{{}, {{"preconvolve.dst", GL_WRITE_ONLY}, {"preconvolve.src", GL_READ_ONLY}}};
    u1.own = {{"preconvolve.dst", &scratch}, {"preconvolve.src", &pyramid}};
    Defines level0 = ctx.defines;
    level0["LEVEL0"] = "1";
    u0.add_unit_defines(level0);
    const GLuint prog0 = ctx.shaders.program({shader}, level0);
    glUseProgram(prog0);
    u0.bind_by_name(ctx.resources, prog0, shader);
    dispatch_2d(pyramid.width(), pyramid.height(), layers, 8, 8);

    GLuint axis_prog[2];
    for (int axis = 0; axis < 2; ++axis) {
        Defines d = ctx.defines;
        d["LEVEL0"] = "0";
        d["AXIS"] = std::to_string(axis);
        u1.add_unit_defines(d);
        axis_prog[axis] = ctx.shaders.program({shader}, d);
        u1.check(axis_prog[axis], shader);
    }
    const GLuint src = u1.image_unit("preconvolve.src"), dst = u1.image_unit("preconvolve.dst");
    for (int level = 1; level < pyramid.levels(); ++level) {
        const int w_in = std::max(pyramid.width() >> (level - 1), 1), h_in = std::max(pyramid.height() >> (level - 1), 1);
        const int w_out = std::max(pyramid.width() >> level, 1), h_out = std::max(pyramid.height() >> level, 1);
        // x: level n-1 (w_in x h_in) -> scratch (w_out x h_in)
        glUseProgram(axis_prog[0]);
        glUniform2i(glGetUniformLocation(axis_prog[0], "u_src_size"), w_in, h_in);
        glUniform2i(glGetUniformLocation(axis_prog[0], "u_dst_size"), w_out, h_in);
        bind_image_layered(src, pyramid, GL_READ_ONLY, level - 1);
        bind_image_layered(dst, scratch, GL_WRITE_ONLY, 0);
        dispatch_2d(w_out, h_in, layers, 8, 8);
        // y: scratch (w_out x h_in) -> level n (w_out x h_out)
        glUseProgram(axis_prog[1]);
        glUniform2i(glGetUniformLocation(axis_prog[1], "u_src_size"), w_out, h_in);
        glUniform2i(glGetUniformLocation(axis_prog[1], "u_dst_size"), w_out, h_out);
        bind_image_layered(src, scratch, GL_READ_ONLY, 0);
        bind_image_layered(dst, pyramid, GL_WRITE_ONLY, level);
        dispatch_2d(w_out, h_out, layers, 8, 8);
    }
}

SSR_REGISTER_PASS(PreconvolvePass());

}  // namespace ssr
