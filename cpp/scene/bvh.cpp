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

struct Device {
    RTCDevice device = rtcNewDevice(nullptr);
    ~Device() {
        if (device) rtcReleaseDevice(device);
    }
};

}  // namespace

Bvh build_bvh(const Scene& scene) {
    // Every triangle of every object, in world space.
    std::vector<BvhTriangle> tris;
    tris.reserve(scene.triangle_count());
    for (size_t o = 0; o < scene.objects.size(); ++o) {
        const Object& obj = scene.objects[o];
        const Mesh& mesh = scene.meshes[size_t(obj.mesh)];
        std::vector<glm::vec3> world(mesh.positions.size());
        for (size_t i = 0; i < world.size(); ++i) world[i] = glm::vec3(obj.transform * glm::vec4(mesh.positions[i], 1.0f));
        for (size_t t = 0; t < mesh.triangle_count(); ++t) {
            BvhTriangle tri{};
            const glm::vec3 &a = world[mesh.indices[3 * t]], &b = world[mesh.indices[3 * t + 1]],
                            &c = world[mesh.indices[3 * t + 2]];
            for (int k = 0; k < 3; ++k) {
                tri.v0[k] = a[k];
                tri.v1[k] = b[k];
                tri.v2[k] = c[k];
            }
            tri.object = int32_t(o);
            tri.primitive = int32_t(t);
            tri.alpha_tested = obj.material >= 0 && scene.materials[size_t(obj.material)].visibility_cutoff() >= 0.0f;
            tris.push_back(tri);
        }
    }
    Bvh bvh;
    if (tris.empty()) return bvh;

    std::vector<RTCBuildPrimitive> prims(tris.size());
    for (size_t i = 0; i < tris.size(); ++i) {
        const BvhTriangle& t = tris[i];
        RTCBuildPrimitive& p = prims[i];
        p.lower_x = std::min({t.v0[0], t.v1[0], t.v2[0]});
        p.lower_y = std::min({t.v0[1], t.v1[1], t.v2[1]});
        p.lower_z = std::min({t.v0[2], t.v1[2], t.v2[2]});
        p.upper_x = std::max({t.v0[0], t.v1[0], t.v2[0]});
        p.upper_y = std::max({t.v0[1], t.v1[1], t.v2[1]});
        p.upper_z = std::max({t.v0[2], t.v1[2], t.v2[2]});
        p.geomID = 0;
        p.primID = unsigned(i);
    }
    const RTCBounds root_bounds = [&] {
        RTCBounds b{};
        b.lower_x = b.lower_y = b.lower_z = 1e30f;
        b.upper_x = b.upper_y = b.upper_z = -1e30f;
        for (const auto& p : prims) {
            b.lower_x = std::min(b.lower_x, p.lower_x);
            b.lower_y = std::min(b.lower_y, p.lower_y);
            b.lower_z = std::min(b.lower_z, p.lower_z);
            b.upper_x = std::max(b.upper_x, p.upper_x);
            b.upper_y = std::max(b.upper_y, p.upper_y);
            b.upper_z = std::max(b.upper_z, p.upper_z);
        }
        return b;
    }();

    Device dev;
    if (!dev.device) throw std::runtime_error("Embree: rtcNewDevice failed");
    RTCBVH handle = rtcNewBVH(dev.device);
    RTCBuildArguments args = rtcDefaultBuildArguments();
    args.buildQuality = RTC_BUILD_QUALITY_HIGH;
    args.maxBranchingFactor = 2;
    args.maxDepth = 48;  // below the GLSL traversal stack of 64
    args.minLeafSize = 1;
    args.maxLeafSize = 4;
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
        throw std::runtime_error("Embree: rtcBuildBVH failed (error " + std::to_string(rtcGetDeviceError(dev.device)) + ")");
    }

    // Flatten depth-first: a node's own bounds travel with it.
    std::function<int32_t(const BuildNode*, const RTCBounds&, int)> flatten = [&](const BuildNode* n,
                                                                                const RTCBounds& b, int depth) {
        bvh.depth = std::max(bvh.depth, depth);
        const int32_t index = int32_t(bvh.nodes.size());
        bvh.nodes.push_back(BvhNode{});
        BvhNode node{};
        node.lo[0] = b.lower_x;
        node.lo[1] = b.lower_y;
        node.lo[2] = b.lower_z;
        node.hi[0] = b.upper_x;
        node.hi[1] = b.upper_y;
        node.hi[2] = b.upper_z;
        if (n->leaf) {
            const auto* leaf = static_cast<const BuildLeaf*>(n);
            node.first = int32_t(bvh.triangles.size());
            node.second = -int32_t(leaf->count);
            for (unsigned i = 0; i < leaf->count; ++i) bvh.triangles.push_back(tris[leaf->ids[i]]);
        } else {
            const auto* inner = static_cast<const BuildInner*>(n);
            node.first = flatten(inner->children[0], inner->bounds[0], depth + 1);
            node.second = flatten(inner->children[1], inner->bounds[1], depth + 1);
        }
        bvh.nodes[size_t(index)] = node;
        return index;
    };
    flatten(root, root_bounds, 1);
    rtcReleaseBVH(handle);
    return bvh;
}

}  // namespace ssr
