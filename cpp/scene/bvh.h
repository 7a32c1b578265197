// A binary BVH over every triangle of a scene in world space, for the reference tracer's
// GLSL traversal (shaders/lib/bvh.glsl). Built with Embree's generic SAH builder
// (rtcBuildBVH), which we hand our own node layout, then flattened depth-first.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/scene.h"

namespace ssr {

// std430 layouts of shaders/lib/bvh.glsl.
struct BvhNode {
    float lo[3];
    int32_t first;   // inner: left child; leaf: first triangle
    float hi[3];
    int32_t second;  // inner: right child; leaf: -(triangle count)
};

struct BvhTriangle {
    float v0[3];
    int32_t object;     // index into Scene::objects
    float v1[3];
    int32_t primitive;  // triangle index within the object's mesh
    float v2[3];
    int32_t alpha_tested;  // 1: its material is MASK or BLEND (the traversals test its alpha)
};

struct Bvh {
    std::vector<BvhNode> nodes;          // nodes[0] is the root (empty when the scene is)
    std::vector<BvhTriangle> triangles;  // in leaf order
    int depth = 0;
};

// Throws std::runtime_error when Embree fails.
Bvh build_bvh(const Scene& scene);

}  // namespace ssr
