#include "passes/lighting.h"

#include "passes/compute.h"

#include <algorithm>

namespace ssr {

std::vector<std::string> LightingPass::inputs() const {
    std::vector<std::string> in = {"gbuffer.depth", "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"};
    if (shadows_) in.push_back("shadow_map");
    return in;
}

std::vector<ResourceDesc> LightingPass::outputs(const RenderSettings& s) const {
    return {{"lit", GL_RGBA16F, s.width, s.height, s.layers, 1},
            {"linear_depth", GL_R32F, s.width, s.height, s.layers, 1}};
}

void LightingPass::execute(FrameContext& ctx) {
    Defines d = ctx.defines;
    d["SHADOWS"] = shadows_ ? "1" : "0";
    const GLuint prog = ctx.shaders.program({"passes/lighting.comp"}, d);
    glUseProgram(prog);
    auto& r = ctx.resources;
    glBindTextureUnit(0, r.get("gbuffer.depth").id());
    glBindTextureUnit(1, r.get("gbuffer.albedo").id());
    glBindTextureUnit(2, r.get("gbuffer.normal").id());
    glBindTextureUnit(3, r.get("gbuffer.material").id());
    if (shadows_) glBindTextureUnit(4, r.get("shadow_map").id());
    bind_image_layered(0, r.get("lit"), GL_WRITE_ONLY);
    bind_image_layered(1, r.get("linear_depth"), GL_WRITE_ONLY);
    // Issue 11: layers behind the first empty one hold nothing anywhere (peeling skipped their
    // draws), so they get exactly what the shader writes for an uncovered pixel, by a clear.
    // Reading the query results waits for the peeling (a sync point before this pass).
    const int allocated = ctx.settings.layers;
    int shaded = allocated;
    if (ctx.settings.skip && peel_) {
        const std::vector<uint64_t> samples = peel_->layer_samples();
        shaded = 0;
        while (shaded < int(samples.size()) && samples[size_t(shaded)] > 0) ++shaded;
        shaded = std::min(shaded, allocated);
    }
    if (shaded < allocated) {
        const Texture& lit = r.get("lit");
        const Texture& depth = r.get("linear_depth");
        const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
        const float far = ctx.uniforms.clip.y;
        glClearTexSubImage(lit.id(), 0, 0, 0, shaded, lit.width(), lit.height(), allocated - shaded, GL_RGBA, GL_FLOAT, zero);
        glClearTexSubImage(depth.id(), 0, 0, 0, shaded, depth.width(), depth.height(), allocated - shaded, GL_RED, GL_FLOAT,
                           &far);
    }
    layers_shaded_ = shaded;
    if (shaded > 0) dispatch_2d(ctx.settings.width, ctx.settings.height, shaded, 8, 8);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
}

}  // namespace ssr
