// reference: ground-truth reflections traced against the scene's triangles on the GPU
// (shaders/passes/reference.comp; BVH from cpp/scene/bvh.cpp). Not part of a frame's chain:
// Renderer::reference runs it on a frame that has been rendered, reading that frame's
// G-buffer, shadow map and rays.
//   per-ray mode   inputs : linear_depth, gbuffer.*, rays.direction, rays.sample (+ shadow_map)
//                  outputs: reference.hit (x, y pixels, object + 1, t), reference.position
//                           (view-space hit, on-screen flag), reference.radiance (rgb, weight),
//                           at the trace resolution, one layer per ray
//   converged mode inputs : linear_depth, gbuffer.* (+ shadow_map)
//                  outputs: reference.accum (sum w c, sum w), reference.reflection, reference.direct
//                           (the pixel's own direct light at its exact point), full resolution
// Shadows come from the frame's shadow map, or from shadow rays traced against the triangles
// (traced_shadows: exact, the reference's default).
#pragma once

#include <functional>

#include "passes/compute.h"
#include "render/render_pass.h"
#include "scene/embree_scene.h"

namespace ssr {

class ReferencePass : public RenderPass {
public:
    // shadows: the frame has a shadowed light; traced_shadows: trace its shadows instead of
    // reading the frame's shadow map.
    ReferencePass(bool per_ray, bool shadows, bool traced_shadows, int rays, bool viewer_is_ray)
        : per_ray_(per_ray), shadows_(shadows), traced_shadows_(traced_shadows), viewer_is_ray_(viewer_is_ray),
          rays_(rays) {}
    std::string name() const override { return "reference"; }
    // On request only (Renderer::reference), never in a frame's chain.
    bool runs(const RenderSettings&, const FrameFacts&) const override { return false; }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override;
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override;
    void execute(FrameContext& ctx) override;
    // Compiles the program before the timed execution.
    GLuint program(FrameContext& ctx) const;
    // What the program reads and writes, by name (passes/compute.h).
    NamedUnits units(const FrameContext& ctx) const;
    // The converged reference's rays traced by `tracer` (Embree, on the CPU) instead of the GLSL
    // BVH: a wavefront whose ray generation and shading stay in the GLSL source
    // (lib/trace_external.glsl). nullptr: the GLSL traversal.
    void set_tracer(const EmbreeTracer* tracer) { tracer_ = tracer; }
    // The converged reference traced by Embree and shaded in C++ on every core
    // (passes/reference_cpu.h), the GLSL only decoding the G-buffer; needs traced shadows or none.
    // environment_type: the scene's (ENVIRONMENT_TYPE); environment_map: its texture or 0.
    void set_cpu_tracer(const EmbreeTracer* tracer, int environment_type, GLuint environment_map) {
        cpu_tracer_ = tracer;
        environment_type_ = environment_type;
        environment_map_ = environment_map;
    }
    // Called after every sample round (rays done, rays asked); returning false stops the pass
    // there (its outputs are then incomplete and must not be used).
    void set_progress(std::function<bool(int, int)> progress) { progress_ = std::move(progress); }
    bool completed() const { return completed_; }
    // Wall milliseconds of the wavefront's stages (empty for the GLSL traversal).
    const std::map<std::string, double>& stage_ms() const { return stage_ms_; }

private:
    void execute_wavefront(FrameContext& ctx, GLuint prog);
    void execute_cpu(FrameContext& ctx, GLuint prog);
    bool per_ray_, shadows_, traced_shadows_, viewer_is_ray_;
    int rays_;
    const EmbreeTracer* tracer_ = nullptr;
    const EmbreeTracer* cpu_tracer_ = nullptr;
    int environment_type_ = 0;
    GLuint environment_map_ = 0;
    std::function<bool(int, int)> progress_;
    bool completed_ = true;
    std::map<std::string, double> stage_ms_;
};

}  // namespace ssr
