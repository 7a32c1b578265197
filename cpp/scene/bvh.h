// A binary BVH over every triangle of a scene in world space, for the reference tracer's
// GLSL traversal (shaders/lib/bvh.glsl), in two levels: each object's triangles have their own
// tree (its BLAS), built with Embree's generic SAH builder (rtcBuildBVH) over the object's
// world-space triangles, and a top tree over the objects' boxes (the TLAS) joins them. Both
// are flattened into one node array whose top leaves are the objects' roots, so the traversal
// sees one ordinary binary BVH. A moved object rebuilds its own tree and the top tree only:
// the cost follows the triangles that moved, and the result is the very tree a fresh build of
// the new state makes (the same builder over the same world-space triangles), so frames after
// a move equal a fresh renderer's bit for bit.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "render/gpu_structs.h"
#include "scene/scene.h"

namespace ssr {

// BvhNode and BvhTriangle, the std430 records lib/bvh.glsl reads, are rows of
// render/gpu_structs.def (the C++ struct and the GLSL declaration both generated from them).

// The element ranges of the node and triangle arrays an update rewrote (what to upload).
struct BvhRange {
    size_t first = 0, count = 0;
};

class SceneBvh {
public:
    // Builds every object's tree and the top tree. Throws std::runtime_error when Embree fails.
    explicit SceneBvh(const Scene& scene);
    ~SceneBvh();
    SceneBvh(const SceneBvh&) = delete;
    SceneBvh& operator=(const SceneBvh&) = delete;

    // Rebuilds the trees of `objects` from their current transforms (their triangles keep
    // their place in triangles(): the object's segment) and the top tree. Returns the
    // triangles rebuilt.
    size_t update(const Scene& scene, const std::vector<int>& objects);
    // Sets the alpha-tested flag of an object's triangles (its material changed).
    void set_alpha_tested(int object, bool alpha_tested);

    const std::vector<BvhNode>& nodes() const { return nodes_; }        // nodes_[0] is the root
    const std::vector<BvhTriangle>& triangles() const { return triangles_; }  // each object's in a segment
    int depth() const { return depth_; }
    size_t object_count() const { return segments_.size(); }
    // Object i's triangles: triangles()[first_triangle(i) ... + triangle_count(i)), in its tree's leaf order.
    size_t first_triangle(int i) const { return segments_[size_t(i)].first_triangle; }
    size_t triangle_count(int i) const { return segments_[size_t(i)].triangles; }

    // What the updates since the last call rewrote: node and triangle ranges; `all_nodes` when
    // the node array grew (a tree outgrew its place and moved to the end): upload it whole.
    struct Changes {
        std::vector<BvhRange> nodes, triangles;
        bool all_nodes = false;
    };
    Changes take_changes();

private:
    struct Segment {
        size_t first_triangle = 0, triangles = 0;
        size_t first_node = 0, node_capacity = 0, node_count = 0;
        int depth = 0;  // its root node holds the object's world bounds
    };
    void build_object(const Scene& scene, int object, bool place_at_end);
    void build_top();
    struct Builder;
    std::unique_ptr<Builder> builder_;
    std::vector<BvhNode> nodes_;
    std::vector<BvhTriangle> triangles_;
    std::vector<Segment> segments_;
    size_t top_nodes_ = 0;  // nodes_[0, top_nodes_): the top tree (its root first)
    int depth_ = 0;
    Changes changes_;
};

}  // namespace ssr
