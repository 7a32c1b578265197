// fallback_probes: reflection probes, the middle level of seed 004's hierarchy (screen space ->
// local cube map -> global cube map). shaders/passes/fallback_probes.comp.
//   capture (once per scene content + probe set, cached on the renderer, not per frame): at
//     each probe, a cube map of lit colour (rgb) and hit distance (a), one BVH ray per texel
//     shaded by the G-buffer's own shading code (lib/trace_shade.glsl), then a mip chain
//     (the roughness pre-filter). The renderer counts a capture as a first-use cost: it is never
//     in a frame's timings, and frame.stats["probe_capture_ms"] reports it on the render that
//     captured.
//   lookup (every frame, after a screen-space tracer): each ray screen space did not resolve
//     (a miss or a faded hit; no confidence test: a probe cannot replace a doubtful hit, see
//     the shader) takes the nearest probe, box-projected on the scene bounds and refined by the
//     probe's distances, at the mip of its roughness cone; where the probe saw the environment
//     it brings the environment.
//     inputs : linear_depth, gbuffer.albedo, gbuffer.normal, gbuffer.material, rays.hit,
//              rays.sample, rays.direction (+ shadow_map for the capture)
//     outputs: rays.radiance (as fallback_bvh: rgb the probe's radiance, a the distance to the
//              estimated hit, -1 the environment, -2 not a fallback ray).
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "render/render_pass.h"

namespace ssr {

class FallbackProbesPass : public RenderPass {
public:
    ~FallbackProbesPass();
    std::string name() const override { return "fallback_probes"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override {
        // Seed 004's local cube maps for what screen space did not resolve; with or without the shadow map.
        return f.reflections && s.method != TraceMethod::Bvh && s.fallback == Fallback::Probes;
    }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override;
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override;
    void execute(FrameContext& ctx) override;

    // Where the probes of `scene` go: Scene.probes (each must lie inside the bounds: throws
    // std::invalid_argument naming the probe), else a probe_grid^3 grid of cell centres.
    static std::vector<glm::vec3> positions(const Scene& scene, const Bounds& bounds, const RenderSettings& s);
    // Captures so far (the renderer reruns a timed chain that captured) and the last one's cost.
    uint64_t captures() const { return captures_; }
    // A bad probe position is the user's error, raised before any pass runs.
    void check(const Scene& scene, const GpuScene& gs, const RenderSettings& s) override {
        positions(scene, gs.bounds(), s);
        captures_at_check_ = captures_;
    }
    // A probe capture (once per scene and probe set) is a first-use cost.
    uint64_t first_uses() const override { return captures_; }
    // The one-time capture's cost (wall clock around the finished GPU work) on the render that
    // captured; 0 when the cached probes served.
    void report(const RenderSettings&, std::map<std::string, double>& stats) const override {
        stats["probes"] = double(probes_.size());
        stats["probe_capture_ms"] = captures_ != captures_at_check_ ? capture_ms_ : 0.0;
    }
    double last_capture_ms() const { return capture_ms_; }
    int probe_count() const { return int(probes_.size()); }
    void release() override;

private:
    void capture(FrameContext& ctx, const std::vector<glm::vec3>& probes);

    GLuint cube_ = 0;        // GL_TEXTURE_CUBE_MAP_ARRAY, RGBA16F, 6 faces per probe, mip chain
    GLuint probe_ssbo_ = 0;  // probe centres (vec4)
    std::string key_;        // what the cached capture was made of
    std::vector<glm::vec3> probes_;
    uint64_t captures_ = 0, captures_at_check_ = 0;
    double capture_ms_ = 0.0;
};

}  // namespace ssr
