#include "passes/lighting.h"

#include "render/pass_registry.h"

#include "passes/gbuffer_layout.h"
#include "passes/compute.h"
#include "passes/shadow_map.h"

#include <algorithm>
#include <optional>

namespace ssr {

std::vector<std::string> LightingPass::inputs(const RenderSettings& s, const FrameFacts& f) const {
    std::vector<std::string> in = {"gbuffer.depth", "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"};
    for (const auto& t : ShadowMapPass::reads(f)) in.push_back(t);
    if (f.emission_texture) in.push_back("gbuffer.emission");  // instead of the factor by object id
    if (f.specular_texture) in.push_back("gbuffer.specular");  // F0 per texel (lib/gbuffer_specular.glsl)
    return in;
}

std::vector<ResourceDesc> LightingPass::outputs(const RenderSettings& s) const {
    return {lit_texture(s), linear_depth_texture(s)};
}

void LightingPass::execute(FrameContext& ctx) {
    Defines d = ctx.defines;
    d["SHADOWS"] = ctx.facts.shadows ? "1" : "0";
    if (ctx.facts.emission_texture) d["EMISSION_TEXTURE"] = "1";  // lib/gbuffer_emission.glsl
    ShadowMapPass::add_defines(d, ctx.facts);
    if (ctx.facts.specular_texture) d["SPECULAR_TEXTURE"] = "1";  // lib/gbuffer_specular.glsl
    // The PCF radius compiled in, so that llvmpipe runs unrolled taps with constant
    // weights instead of two nested loops over a uniform bound.
    if (ctx.facts.shadows) d["SHADOW_PCF_RADIUS"] = std::to_string(ctx.settings.shadow_pcf_radius);
    // One indirect dispatch over the 8x8 tiles of every layer the peeling covered (its
    // "covered_tiles"); the rest is cleared. llvmpipe runs each SIMD vector through every branch,
    // so an uncovered texel cost as much as a covered one (4 layers of spheres_and_boxes, 59 %
    // to 2 % covered, cost as much as hall's, 94 % to 37 %).
    const FrameBuffer& tiles = ctx.buffers.get("covered_tiles");
    tiles_ = tiles.data;
    const int tile_count = DepthPeelPass::covered_tiles_per_layer(ctx.settings) * ctx.settings.layers;
    // Its parts (lighting.list/clear/shade): where the pass's time goes on a device.
    std::optional<GpuScope> part;
    part.emplace(ctx.timer, "lighting.list");
    // Both programs declare the inputs (the normals by imageLoad on the CPU device,
    // lib/input_fetch.glsl; the depth is a depth format, which no image can bind).
    auto& r = ctx.resources;
    NamedUnits units{{"gbuffer.depth", "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"},
                     {{"lit", GL_WRITE_ONLY}, {"linear_depth", GL_WRITE_ONLY}}};
    for (const auto& m : ShadowMapPass::reads(ctx.facts)) units.textures.push_back(m);
    if (ctx.facts.emission_texture) units.textures.push_back("gbuffer.emission");
    if (ctx.facts.specular_texture) units.textures.push_back("gbuffer.specular");
    units.fetch(ctx.fetch_by_image(), {"gbuffer.normal"});
    units.add_unit_defines(d);
    Defines dl = d;
    dl["TILE_LIST"] = "1";
    const GLuint list = ctx.shaders.program({"passes/lighting.comp"}, dl);
    glUseProgram(list);
    glUniform1i(glGetUniformLocation(list, "u_tiles"), tile_count);
    tiles.bind();
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);  // the peeling's fragment writes
    glDispatchCompute(GLuint((tile_count + 63) / 64), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
    // Every layer is cleared first: the tiles the list leaves out keep the clear. With skip, the
    // layers the peeling found non-empty (FrameContext::layers_used) are the ones counted as shaded.
    const int allocated = ctx.settings.layers;
    layers_shaded_ = ctx.settings.skip ? ctx.layers_in_use() : allocated;
    part.emplace(ctx.timer, "lighting.clear");
    const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    const float far[4] = {ctx.uniforms.clip.y, 0.0f, 0.0f, 0.0f};
    clear_layers(ctx, ctx.resources.get("lit"), 0, zero);
    clear_layers(ctx, ctx.resources.get("linear_depth"), 0, far);
    const GLuint prog = ctx.shaders.program({"passes/lighting.comp"}, d);
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_tiles"), tile_count);
    units.bind_by_name(r, prog, "passes/lighting.comp");
    part.emplace(ctx.timer, "lighting.shade");
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);  // the clears first
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, tiles.data->id());
    glDispatchComputeIndirect(0);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
}

int LightingPass::tiles_shaded() const {
    if (!tiles_ || !*tiles_) return -1;
    GLuint header[4] = {0, 0, 0, 0};
    // GL makes the shaders' atomics visible to glGetBufferSubData only after this barrier
    // (llvmpipe finishes every dispatch first; a GPU need not).
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(tiles_->id(), 0, sizeof(header), header);
    return int(header[0]);
}

SSR_REGISTER_PASS(LightingPass());

}  // namespace ssr
