// The scene in an Embree ray-tracing scene (robust mode), for checking the GPU reference
// tracer against a production CPU kernel: closest hits of rays given from Python.
#pragma once

#include <vector>

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

}  // namespace ssr
