#include "passes/fallback_probes.h"

#include "render/pass_registry.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "passes/compute.h"
#include "passes/shadow_map.h"
#include "render/gpu_scene.h"

namespace ssr {

FallbackProbesPass::~FallbackProbesPass() = default;  // GL objects: release() (context current)

void FallbackProbesPass::release() {
    if (cube_) glDeleteTextures(1, &cube_);
    if (probe_ssbo_) glDeleteBuffers(1, &probe_ssbo_);
    cube_ = probe_ssbo_ = 0;
    key_.clear();
    probes_.clear();
}

std::vector<std::string> FallbackProbesPass::inputs(const RenderSettings& s, const FrameFacts& f) const {
    std::vector<std::string> in = {"linear_depth",  "gbuffer.albedo", "gbuffer.normal", "gbuffer.material",
                                   "rays.hit",      "rays.sample",    "rays.direction"};
    if (s.bvh_shadows != BvhShadows::Traced)
        for (const auto& t : ShadowMapPass::reads(f)) in.push_back(t);
    return in;
}

std::vector<ResourceDesc> FallbackProbesPass::outputs(const RenderSettings& s) const {
    return {{"rays.radiance", GL_RGBA32F, s.trace_width(), s.trace_height(), s.traced_rays(), 1}};
}

std::vector<glm::vec3> FallbackProbesPass::positions(const Scene& scene, const Bounds& b, const RenderSettings& s) {
    auto str = [](glm::vec3 v) {
        char buf[96];
        std::snprintf(buf, sizeof(buf), "(%g, %g, %g)", v.x, v.y, v.z);
        return std::string(buf);
    };
    if (b.empty()) throw std::invalid_argument("Settings.fallback 'probes': the scene is empty (no bounds to place probes in)");
    if (!scene.probes.empty()) {
        for (size_t i = 0; i < scene.probes.size(); ++i) {
            const glm::vec3 p = scene.probes[i];
            if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)))
                throw std::invalid_argument("Scene.probes: probe " + std::to_string(i) + " is not finite");
            // Box projection assumes the probe inside its proxy box (the scene bounds): outside
            // it, a lookup direction would point from the probe to a box it is not in.
            if (glm::any(glm::lessThanEqual(p, b.min)) || glm::any(glm::greaterThanEqual(p, b.max)))
                throw std::invalid_argument("Scene.probes: probe " + std::to_string(i) + " at " + str(p) +
                                            " lies outside the scene bounds " + str(b.min) + " - " + str(b.max) +
                                            " (its box-projection proxy); place it strictly inside");
        }
        return scene.probes;
    }
    std::vector<glm::vec3> out;
    const int g = s.probe_grid;
    for (int z = 0; z < g; ++z)
        for (int y = 0; y < g; ++y)
            for (int x = 0; x < g; ++x)
                out.push_back(b.min + (glm::vec3(x, y, z) + 0.5f) / float(g) * (b.max - b.min));
    return out;
}

// The probes are captured with the BVH tracer and the reference's trace-and-shade code
// (lib/trace_shade.glsl), not by rasterising six views and lighting them: it is the simplest
// way to get exactly the shading the lit G-buffer and the BVH fallback give a surface (same
// material, lights, shadow map or traced shadow), needs no extra G-buffer per face, and the
// BVH is already on the GPU for the other hybrid passes. Each texel's surface is viewed from
// the probe's centre (the physical view a cube map stores; seed 004 captures it offline once),
// so a capture depends on the scene and the probe set, not on the camera.
namespace {
// The probes' cube array is the pass's own texture (no frame resource), placed at this texture
// unit for the lookup and this image unit for the capture, by name ("probes").
constexpr GLuint kProbesUnit = 0;

// What both stages declare: the layer-0 G-buffer (by name), and the shadow maps the capture's
// shading reads.
NamedUnits probe_units(const FrameContext& ctx, bool shadow_maps) {
    NamedUnits u{{"linear_depth", "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"}, {}};
    if (shadow_maps)
        for (const auto& m : ShadowMapPass::reads(ctx.facts)) u.textures.push_back(m);
    return u;
}
}  // namespace

void FallbackProbesPass::capture(FrameContext& ctx, const std::vector<glm::vec3>& probes) {
    const RenderSettings& s = ctx.settings;
    const int size = s.probe_size, n = int(probes.size());
    const int levels = 1 + int(std::floor(std::log2(double(size))));
    Defines d = ctx.defines;
    d["STAGE"] = "0";  // capture
    const bool traced = s.bvh_shadows == BvhShadows::Traced;
    const bool shadows = ctx.facts.shadows;
    d["SHADOWS"] = shadows && !traced ? "1" : "0";
    d["TRACED_SHADOWS"] = shadows && traced ? "1" : "0";
    ShadowMapPass::add_defines(d, ctx.facts);
    // A double-sided surface shows the probe the side its ray meets, not the camera's side.
    d["FACING_FROM_RAY"] = "1";
    NamedUnits units = probe_units(ctx, shadows && !traced);
    units.placed_images = {{"probes", kProbesUnit}};
    units.add_unit_defines(d);
    const GLuint prog = ctx.shaders.program({"passes/fallback_probes.comp"}, d);  // compiled outside the clock
    glFinish();
    const auto start = std::chrono::steady_clock::now();
    if (cube_) glDeleteTextures(1, &cube_);
    glCreateTextures(GL_TEXTURE_CUBE_MAP_ARRAY, 1, &cube_);
    glTextureStorage3D(cube_, levels, GL_RGBA16F, size, size, 6 * n);
    glTextureParameteri(cube_, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTextureParameteri(cube_, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(cube_, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(cube_, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    std::vector<glm::vec4> centres;
    for (const auto& p : probes) centres.emplace_back(p, 1.0f);
    if (probe_ssbo_) glDeleteBuffers(1, &probe_ssbo_);
    glCreateBuffers(1, &probe_ssbo_);
    glNamedBufferStorage(probe_ssbo_, GLsizeiptr(centres.size() * sizeof(glm::vec4)), centres.data(), 0);

    const_cast<GpuScene&>(ctx.gpu_scene).bind_ray_tracing(ctx.scene);
    glUseProgram(prog);
    units.bind_by_name(ctx.resources, prog, "passes/fallback_probes.comp");
    glBindImageTexture(kProbesUnit, cube_, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA16F);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kProbeCentresBinding, probe_ssbo_);
    glUniform1i(0, size);
    dispatch_2d(size, size, 6 * n, 8, 8);
    // The roughness pre-filter: each level the box average of the one below, per face (seed
    // 004's "mipmap by roughness"); the lookup picks the level whose texel matches the
    // roughness cone's footprint. Box, not a GGX convolution: the cone already decides the
    // footprint and the level is interpolated trilinearly.
    glGenerateTextureMipmap(cube_);
    glFinish();
    capture_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    ++captures_;
    probes_ = probes;
}

void FallbackProbesPass::execute(FrameContext& ctx) {
    const RenderSettings& s = ctx.settings;
    const Bounds& b = ctx.gpu_scene.bounds();
    const std::vector<glm::vec3> probes = positions(ctx.scene, b, s);
    // The capture's cache key: everything that changes what a probe sees.
    std::string key = std::to_string(ctx.scene.id()) + "/" + std::to_string(ctx.scene.revision()) + "/" +
                      std::to_string(s.probe_size) + "/" + std::to_string(int(s.bvh_shadows)) + "/" +
                      std::to_string(s.shadow_map_size) + "/" + std::to_string(s.shadow_normal_offset) + "/" +
                      std::to_string(s.shadow_pcf_radius) + "/" + std::to_string(s.max_distance) + "/" +
                      std::to_string(ctx.facts.shadow_maps) + "s" + std::to_string(ctx.facts.shadow_cubes) + "c";
    for (const auto& p : probes) key += "/" + std::to_string(p.x) + "," + std::to_string(p.y) + "," + std::to_string(p.z);
    if (key != key_ || !cube_) {
        capture(ctx, probes);
        key_ = key;
    }

    auto& r = ctx.resources;
    Defines d = ctx.defines;
    d["STAGE"] = "1";  // lookup
    d["SHADOWS"] = "0";
    d["TRACED_SHADOWS"] = "0";
    NamedUnits units = probe_units(ctx, false);
    units.textures.insert(units.textures.end(), {"rays.sample", "rays.direction"});
    units.images = {{"rays.hit", GL_READ_ONLY}, {"rays.radiance", GL_WRITE_ONLY}};
    units.placed_textures = {{"probes", kProbesUnit}};
    units.add_unit_defines(d);
    const GLuint prog = ctx.shaders.program({"passes/fallback_probes.comp"}, d);
    glUseProgram(prog);
    units.bind_by_name(r, prog, "passes/fallback_probes.comp");
    glBindTextureUnit(kProbesUnit, cube_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kProbeCentresBinding, probe_ssbo_);
    glUniform1i(0, s.probe_size);
    glUniform1i(1, int(probes_.size()));
    glUniform3fv(2, 1, &b.min.x);
    glUniform3fv(3, 1, &b.max.x);
    dispatch_2d(s.trace_width(), s.trace_height(), s.traced_rays(), 8, 8);
}

SSR_REGISTER_PASS(FallbackProbesPass());

}  // namespace ssr
