#include "scene/bvh.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <functional>
#include <new>
#include <stdexcept>
#include <string>

namespace ssr {

namespace {

// Nodes of the builder's tree, allocated by Embree's thread-local allocator and freed with
// the RTCBVH: no destructors run, so they hold plain data only.
struct BuildNode {
    bool leaf;
};

struct BuildInner : BuildNode {
    BuildNode* children[2];
    RTCBounds bounds[2];
};

struct BuildLeaf : BuildNode {
    unsigned count;
    unsigned ids[RTC_BUILD_MAX_PRIMITIVES_PER_LEAF];
};

void* create_node(RTCThreadLocalAllocator alloc, unsigned int child_count, void*) {
    void* mem = rtcThreadLocalAlloc(alloc, sizeof(BuildInner), 16);
    auto* n = new (mem) BuildInner;
    n->leaf = false;
    n->children[0] = n->children[1] = nullptr;
    return n;
}

void set_children(void* node, void** children, unsigned int count, void*) {
    auto* n = static_cast<BuildInner*>(node);
    for (unsigned i = 0; i < count && i < 2; ++i) n->children[i] = static_cast<BuildNode*>(children[i]);
}

void set_bounds(void* node, const RTCBounds** bounds, unsigned int count, void*) {
    auto* n = static_cast<BuildInner*>(node);
    for (unsigned i = 0; i < count && i < 2; ++i) n->bounds[i] = *bounds[i];
}

void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void*) {
    void* mem = rtcThreadLocalAlloc(alloc, sizeof(BuildLeaf), 16);
    auto* leaf = new (mem) BuildLeaf;
    leaf->leaf = true;
    leaf->count = unsigned(std::min<size_t>(count, RTC_BUILD_MAX_PRIMITIVES_PER_LEAF));
    for (unsigned i = 0; i < leaf->count; ++i) leaf->ids[i] = prims[i].primID;
    return leaf;
}

}  // namespace

namespace {

// An empty box, and a box grown to hold a primitive's.
RTCBounds empty_bounds() {
    RTCBounds b{};
    b.lower_x = b.lower_y = b.lower_z = 1e30f;
    b.upper_x = b.upper_y = b.upper_z = -1e30f;
    return b;
}
void grow_bounds(RTCBounds& b, const RTCBuildPrimitive& p) {
    b.lower_x = std::min(b.lower_x, p.lower_x);
    b.lower_y = std::min(b.lower_y, p.lower_y);
    b.lower_z = std::min(b.lower_z, p.lower_z);
    b.upper_x = std::max(b.upper_x, p.upper_x);
    b.upper_y = std::max(b.upper_y, p.upper_y);
    b.upper_z = std::max(b.upper_z, p.upper_z);
}

}  // namespace

// Embree's device, kept for the scene's life: every update builds with it.
struct SceneBvh::Builder {
    RTCDevice device = rtcNewDevice(nullptr);
    Builder() {
        if (!device) throw std::runtime_error("Embree: rtcNewDevice failed");
    }
    ~Builder() { rtcReleaseDevice(device); }

    // A binary SAH tree over `prims` (their primID: the caller's item index), handed to
    // `use(root, root_bounds)` while the builder's nodes live.
    template <typename Use>
    void build(std::vector<RTCBuildPrimitive>& prims, unsigned max_leaf, unsigned max_depth, Use&& use) {
        RTCBounds root_bounds = empty_bounds();
        for (const auto& p : prims) grow_bounds(root_bounds, p);
        RTCBVH handle = rtcNewBVH(device);
        RTCBuildArguments args = rtcDefaultBuildArguments();
        args.buildQuality = RTC_BUILD_QUALITY_HIGH;
        args.maxBranchingFactor = 2;
        args.maxDepth = max_depth;
        args.minLeafSize = 1;
        args.maxLeafSize = max_leaf;
        args.traversalCost = 1.0f;
        args.intersectionCost = 1.0f;
        args.bvh = handle;
        args.primitives = prims.data();
        args.primitiveCount = prims.size();
        args.primitiveArrayCapacity = prims.size();
        args.createNode = create_node;
        args.setNodeChildren = set_children;
        args.setNodeBounds = set_bounds;
        args.createLeaf = create_leaf;
        auto* root = static_cast<BuildNode*>(rtcBuildBVH(&args));
        if (!root) {
            rtcReleaseBVH(handle);
            throw std::runtime_error("Embree: rtcBuildBVH failed (error " + std::to_string(rtcGetDeviceError(device)) +
                                     ")");
        }
        try {
            use(root, root_bounds);
        } catch (...) {
            rtcReleaseBVH(handle);
            throw;
        }
        rtcReleaseBVH(handle);
    }
};

namespace {

// Depth limits of the two levels: together within the GLSL traversal's stack of 64 entries
// (lib/bvh.glsl's BVH_STACK; a binary traversal holds at most one pending node per level).
constexpr unsigned kObjectTreeDepth = 40, kTopTreeDepth = 23;
constexpr int kMaxTotalDepth = 63;

void set_node_bounds(BvhNode& node, const RTCBounds& b) {
    node.lo[0] = b.lower_x;
    node.lo[1] = b.lower_y;
    node.lo[2] = b.lower_z;
    node.hi[0] = b.upper_x;
    node.hi[1] = b.upper_y;
    node.hi[2] = b.upper_z;
}

}  // namespace

SceneBvh::SceneBvh(const Scene& scene) : builder_(std::make_unique<Builder>()) {
    segments_.resize(scene.objects.size());
    size_t first = 0;
    for (size_t o = 0; o < scene.objects.size(); ++o) {
        segments_[o].first_triangle = first;
        segments_[o].triangles = scene.meshes[size_t(scene.objects[o].mesh)].triangle_count();
        first += segments_[o].triangles;
    }
    triangles_.resize(first);
    if (segments_.empty()) return;
    // The top tree's place first (its root is node 0), then every object's tree in object order.
    top_nodes_ = std::max<size_t>(segments_.size() - 1, 1);
    nodes_.resize(top_nodes_);
    for (size_t o = 0; o < segments_.size(); ++o) build_object(scene, int(o), true);
    build_top();
    changes_ = Changes{};
}

SceneBvh::~SceneBvh() = default;

void SceneBvh::build_object(const Scene& scene, int object, bool place_at_end) {
    Segment& seg = segments_[size_t(object)];
    const Object& obj = scene.objects[size_t(object)];
    const Mesh& mesh = scene.meshes[size_t(obj.mesh)];
    std::vector<glm::vec3> world(mesh.positions.size());
    for (size_t i = 0; i < world.size(); ++i) world[i] = glm::vec3(obj.transform * glm::vec4(mesh.positions[i], 1.0f));
    const int32_t alpha = obj.material >= 0 && scene.materials[size_t(obj.material)].visibility_cutoff() >= 0.0f;
    std::vector<BvhTriangle> tris(seg.triangles);
    std::vector<RTCBuildPrimitive> prims(seg.triangles);
    for (size_t t = 0; t < seg.triangles; ++t) {
        BvhTriangle& tri = tris[t];
        const glm::vec3 &a = world[mesh.indices[3 * t]], &b = world[mesh.indices[3 * t + 1]],
                        &c = world[mesh.indices[3 * t + 2]];
        for (int k = 0; k < 3; ++k) {
            tri.v0[k] = a[k];
            tri.v1[k] = b[k];
            tri.v2[k] = c[k];
        }
        tri.object = int32_t(object);
        tri.primitive = int32_t(t);
        tri.alpha_tested = alpha;
        RTCBuildPrimitive& p = prims[t];
        p.lower_x = std::min({a.x, b.x, c.x});
        p.lower_y = std::min({a.y, b.y, c.y});
        p.lower_z = std::min({a.z, b.z, c.z});
        p.upper_x = std::max({a.x, b.x, c.x});
        p.upper_y = std::max({a.y, b.y, c.y});
        p.upper_z = std::max({a.z, b.z, c.z});
        p.geomID = 0;
        p.primID = unsigned(t);
    }

    // Flattened depth-first into a local array (children and triangles relative to the object's
    // own places), then moved into its segment.
    std::vector<BvhNode> local;
    size_t placed = 0;
    int depth = 0;
    builder_->build(prims, 4, kObjectTreeDepth, [&](const BuildNode* root, const RTCBounds& root_bounds) {
        std::function<int32_t(const BuildNode*, const RTCBounds&, int)> flatten = [&](const BuildNode* n,
                                                                                    const RTCBounds& b, int d) {
            depth = std::max(depth, d);
            const int32_t index = int32_t(local.size());
            local.push_back(BvhNode{});
            BvhNode node{};
            set_node_bounds(node, b);
            if (n->leaf) {
                const auto* leaf = static_cast<const BuildLeaf*>(n);
                node.first = int32_t(placed);
                node.second = -int32_t(leaf->count);
                for (unsigned i = 0; i < leaf->count; ++i) triangles_[seg.first_triangle + placed++] = tris[leaf->ids[i]];
            } else {
                const auto* inner = static_cast<const BuildInner*>(n);
                node.first = flatten(inner->children[0], inner->bounds[0], d + 1);
                node.second = flatten(inner->children[1], inner->bounds[1], d + 1);
            }
            local[size_t(index)] = node;
            return index;
        };
        flatten(root, root_bounds, 1);
    });
    if (placed != seg.triangles) throw std::runtime_error("Embree: the BVH's leaves do not hold every triangle");

    if (place_at_end || local.size() > seg.node_capacity) {
        // Its first place, or a tree that outgrew its place: at the end of the array.
        if (!place_at_end) changes_.all_nodes = true;
        seg.first_node = nodes_.size();
        seg.node_capacity = local.size();
        nodes_.resize(nodes_.size() + local.size());
    }
    seg.node_count = local.size();
    seg.depth = depth;
    for (size_t i = 0; i < local.size(); ++i) {
        BvhNode node = local[i];
        if (node.second < 0) node.first += int32_t(seg.first_triangle);
        else {
            node.first += int32_t(seg.first_node);
            node.second += int32_t(seg.first_node);
        }
        nodes_[seg.first_node + i] = node;
    }
    changes_.nodes.push_back({seg.first_node, seg.node_count});
    changes_.triangles.push_back({seg.first_triangle, seg.triangles});
}

void SceneBvh::build_top() {
    if (segments_.size() == 1) {
        // One object: its tree is the whole BVH, its root copied to node 0.
        nodes_[0] = nodes_[segments_[0].first_node];
        depth_ = segments_[0].depth;
        changes_.nodes.push_back({0, 1});
        return;
    }
    std::vector<RTCBuildPrimitive> prims(segments_.size());
    for (size_t o = 0; o < segments_.size(); ++o) {
        const BvhNode& root = nodes_[segments_[o].first_node];  // its bounds: the object's
        RTCBuildPrimitive& p = prims[o];
        p.lower_x = root.lo[0];
        p.lower_y = root.lo[1];
        p.lower_z = root.lo[2];
        p.upper_x = root.hi[0];
        p.upper_y = root.hi[1];
        p.upper_z = root.hi[2];
        p.geomID = 0;
        p.primID = unsigned(o);
    }
    const std::vector<RTCBuildPrimitive> boxes = prims;  // (the builder reorders `prims`)
    size_t next = 0;  // the next free node of the top tree's place
    int depth = 0;
    builder_->build(prims, 1, kTopTreeDepth, [&](const BuildNode* root, const RTCBounds& root_bounds) {
        // A node of the top tree at nodes_[next], or, for a single object, that object's root:
        // the top leaves are the objects' trees.
        std::function<int32_t(const unsigned*, unsigned, const RTCBounds&, int)> items;
        std::function<int32_t(const BuildNode*, const RTCBounds&, int)> flatten;
        auto inner_node = [&](const RTCBounds& b, auto&& left, auto&& right) {
            const size_t index = next++;
            BvhNode node{};
            set_node_bounds(node, b);
            node.first = left();
            node.second = right();
            nodes_[index] = node;
            return int32_t(index);
        };
        auto bounds_of = [&](const unsigned* ids, unsigned n) {
            RTCBounds b = empty_bounds();
            for (unsigned i = 0; i < n; ++i) grow_bounds(b, boxes[ids[i]]);
            return b;
        };
        items = [&](const unsigned* ids, unsigned n, const RTCBounds& b, int d) -> int32_t {
            if (n == 1) {
                const Segment& s = segments_[ids[0]];
                depth = std::max(depth, d - 1 + s.depth);
                return int32_t(s.first_node);
            }
            // A leaf of several objects (boxes the builder could not part): split in halves.
            const unsigned half = n / 2;
            return inner_node(
                b, [&] { return items(ids, half, bounds_of(ids, half), d + 1); },
                [&] { return items(ids + half, n - half, bounds_of(ids + half, n - half), d + 1); });
        };
        flatten = [&](const BuildNode* n, const RTCBounds& b, int d) -> int32_t {
            if (n->leaf) {
                const auto* leaf = static_cast<const BuildLeaf*>(n);
                return items(leaf->ids, leaf->count, b, d);
            }
            const auto* inner = static_cast<const BuildInner*>(n);
            return inner_node(
                b, [&] { return flatten(inner->children[0], inner->bounds[0], d + 1); },
                [&] { return flatten(inner->children[1], inner->bounds[1], d + 1); });
        };
        flatten(root, root_bounds, 1);
    });
    if (next != top_nodes_) throw std::runtime_error("Embree: the top BVH does not hold every object");
    depth_ = depth;
    if (depth_ > kMaxTotalDepth)
        throw std::runtime_error("the scene's BVH is " + std::to_string(depth_) +
                                 " levels deep, beyond the GLSL traversal's stack");
    changes_.nodes.push_back({0, top_nodes_});
}

size_t SceneBvh::update(const Scene& scene, const std::vector<int>& objects) {
    size_t rebuilt = 0;
    for (int o : objects) {
        build_object(scene, o, false);
        rebuilt += segments_[size_t(o)].triangles;
    }
    if (!objects.empty()) build_top();
    return rebuilt;
}

void SceneBvh::set_alpha_tested(int object, bool alpha_tested) {
    const Segment& seg = segments_[size_t(object)];
    for (size_t t = seg.first_triangle; t < seg.first_triangle + seg.triangles; ++t)
        triangles_[t].alpha_tested = alpha_tested ? 1 : 0;
    changes_.triangles.push_back({seg.first_triangle, seg.triangles});
}

SceneBvh::Changes SceneBvh::take_changes() {
    Changes out = std::move(changes_);
    changes_ = Changes{};
    return out;
}

}  // namespace ssr
