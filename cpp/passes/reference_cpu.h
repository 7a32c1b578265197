// The converged reference on the CPU: Embree traces the rays and C++ shades them, on every core.
// A port of shaders/passes/reference.comp (MODE 1, TRACED_SHADOWS) and the library code it calls
// (lib/ray_generation, ggx_sampling, brdf, material, normal_mapping, scene_geometry,
// scene_textures, shading, environment, ray_offset, trace_shade), formula for formula and in the
// same order of operations, so that the two agree per pixel up to float evaluation order: the
// same rays from the same RNG streams (PCG hashes and Hammersley points are integer-exact), the
// same exact surface point, the same offsets. The G-buffer is decoded by the GLSL itself
// (passes/reference_gbuffer.comp) and read back, so the pixels start from identical samples.
//
// Why a port and not the GLSL replayed around Embree (lib/trace_external.glsl, tracer="embree"):
// on the CPU device llvmpipe executes that GLSL, and measured it is 96 % of the replay's time
// (docs/reference_tracers.md); here each hit is shaded once, with no phases, no read-back of
// queries and no per-phase recomputation of the pixel's set-up.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "render/gpu_structs.h"
#include "render/gpu_scene.h"
#include "render/ssr_uniforms.h"
#include "scene/bvh.h"
#include "scene/embree_scene.h"

namespace ssr {

// Everything the reference shader reads, as host copies (layouts of the GPU buffers).
struct CpuReferenceScene {
    FrameUniforms frame{};
    SsrUniforms ssr{};                // as uploaded for the converged reference
    std::vector<GpuLight> lights;     // view space
    std::vector<GpuObject> objects;
    std::vector<GpuMaterial> materials;
    std::vector<float> vertex_data;   // GpuVertex, kVertexFloats each
    std::vector<uint32_t> index_data;
    std::vector<BvhTriangle> triangles;  // the BVH's (Embree's primitive ids index them)
    std::vector<uint32_t> image_texels;  // RGBA8 packed (lib/scene_textures.glsl)
    std::vector<glm::ivec4> image_info;  // (first texel, width, height, 0)
    int environment_type = 0;            // ENVIRONMENT_TYPE: 0 constant, 1 sky, 2 map
    std::vector<glm::vec4> environment_map;  // level 0 of the map, rows from v = 0
    int environment_width = 0, environment_height = 0;
    bool viewer_is_ray = true;
    const EmbreeTracer* tracer = nullptr;  // Embree's scene over `triangles` (EmbreeTracer::scene)
};

// The G-buffer sample of a pixel as lib/gbuffer.glsl's gbuffer_decode returns it, and the
// pixel's linear depth: three vec4 per pixel (passes/reference_gbuffer.comp).
struct CpuGbufferTexel {
    glm::vec4 albedo_metallic;
    glm::vec4 normal_roughness;
    glm::vec4 material;  // reflectivity, covered (0/1), object id (exact in a float), linear depth
};

class CpuReference {
public:
    // emission: every pixel's gbuffer.emission where the scene has an emissive texture; empty:
    // the material's factor found by object id (lib/gbuffer_emission.glsl).
    CpuReference(const CpuReferenceScene& scene, int width, int height, std::vector<CpuGbufferTexel> gbuffer,
                 std::vector<glm::vec4> emission = {}, std::vector<glm::vec4> dielectric_f0 = {});
    // The exact surface point of every pixel (the camera ray through its centre).
    void begin();
    // Ray indices [first, first + count) of every reflective pixel, added to its sums.
    void trace_rays(int first, int count);
    // The normalised reflection and the pixel's own direct light.
    void finish();
    const std::vector<glm::vec4>& accum() const { return accum_; }
    const std::vector<glm::vec4>& reflection() const { return reflection_; }
    const std::vector<glm::vec4>& direct() const { return direct_; }
    double rays_traced() const { return double(rays_.load()); }

private:
    struct PixelState {
        glm::vec3 pos;       // view space (the exact point where the camera ray finds the G-buffer's object)
        glm::vec3 origin_w;  // reflection rays' origin (exact only)
        glm::vec3 point_w, normal_w;
        bool exact = false;
    };
    void parallel_rows(const std::function<void(int)>& row);
    const CpuReferenceScene& s_;
    int width_, height_;
    std::vector<CpuGbufferTexel> gbuffer_;
    std::vector<glm::vec4> emission_;
    std::vector<glm::vec4> dielectric_f0_;  // every pixel's gbuffer.specular (empty: by object id)
    std::vector<PixelState> state_;
    std::vector<glm::vec4> accum_, reflection_, direct_;
    std::atomic<uint64_t> rays_{0};
};

}  // namespace ssr
