// The scene in an Embree ray-tracing scene (robust mode), for checking the GPU reference
// tracer against a production CPU kernel: closest hits of rays given from Python.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "scene/bvh.h"
#include "scene/scene.h"

namespace ssr {

struct CpuHit {
    float t;          // inf for a miss
    int object;       // -1 for a miss
    int primitive;    // triangle index within the object's mesh
    float u, v;       // Embree's barycentric coordinates
};

// Closest hits of rays (origin, direction) with t in (t_min, t_max), on all cores.
std::vector<CpuHit> embree_intersect(const Scene& scene, const std::vector<glm::vec3>& origins,
                                     const std::vector<glm::vec3>& directions, float t_min, float t_max);

// A ray query of the wavefront reference (std430 layout of shaders/lib/trace_external.glsl):
// kind 0 none, 1 closest hit, 2 any hit (shadow rays).
struct TraceQuery {
    float origin[3];
    float t_min;
    float dir[3];
    float t_max;
    int32_t kind;
    int32_t pad[3];
};

// Its answer, as lib/bvh.glsl's trace_closest reports a hit: t, the triangle's index in the
// BVH's triangle order (-1 for a miss; any triangle >= 0 for an occluded shadow ray) and the
// barycentric weights of its v1 and v2.
struct TraceAnswer {
    float t;
    int32_t triangle;
    float b1, b2;
};

// The BVH's own triangle list (Bvh::triangles, world space, in leaf order) in an Embree scene,
// one geometry whose primitive IDs are those indices, so that Embree's hits name the very
// triangles the GLSL traversal would (and the shading code finds them in bvh_triangles).
// Embree's barycentrics (u, v) weigh v1 and v2, as the GLSL test's b1, b2 do.
class EmbreeTracer {
public:
    explicit EmbreeTracer(const std::vector<BvhTriangle>& triangles);
    ~EmbreeTracer();
    EmbreeTracer(const EmbreeTracer&) = delete;
    EmbreeTracer& operator=(const EmbreeTracer&) = delete;
    // Answers n queries on all cores (threads, each ray by itself: the reflection rays of rough
    // surfaces are incoherent, where Embree's single-ray kernel is its fastest).
    void trace(const TraceQuery* queries, size_t n, TraceAnswer* answers) const;
    // The RTCScene, for callers that trace their own rays (passes/reference_cpu.h).
    const void* scene() const { return scene_; }

private:
    void* device_ = nullptr;  // RTCDevice
    void* scene_ = nullptr;   // RTCScene
};

}  // namespace ssr
