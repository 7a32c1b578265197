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

// The alpha test of glTF MASK materials (BLEND at 0.5) on the CPU, as lib/bvh.glsl's
// bvh_alpha_hole does it: alpha = factor x the base colour texture's alpha, sampled bilinearly at
// level 0 with the texture's wrap modes (scene_textures.glsl's sample_image); below the cutoff
// the hit is a hole and the ray goes on. Copies what it needs, so the Scene may change after.
class AlphaMasks {
public:
    AlphaMasks() = default;
    // For the BVH's triangles (SceneBvh::triangles order); empty when no triangle is alpha-tested.
    AlphaMasks(const Scene& scene, const std::vector<BvhTriangle>& triangles);
    // Recomputes triangles [first, first + count) (an object whose transform or material changed).
    void update(const Scene& scene, const std::vector<BvhTriangle>& triangles, size_t first, size_t count);
    bool empty() const { return triangles_.empty(); }
    // Whether the hit at barycentrics (b1, b2) of BVH triangle `triangle` is a hole.
    bool hole(size_t triangle, float b1, float b2) const;

private:
    struct AlphaImage {
        int width = 0, height = 0;
        std::vector<uint8_t> alpha;  // rows top-first, as Image::rgba
    };
    struct Triangle {
        float cutoff = -1.0f;  // -1: opaque
        float factor = 1.0f;   // base_color.a
        int image = -1;        // into images_, -1: no texture
        int wrap_s = 10497, wrap_t = 10497;
        float uv[6] = {};  // the vertices' texture coordinates (the texture's set), KHR_texture_transform applied
        float vertex_alpha[3] = {1.0f, 1.0f, 1.0f};  // the vertices' COLOR_0 alpha (a factor of the base colour's)

    };
    Triangle triangle(const Scene& scene, const BvhTriangle& bt);
    std::vector<AlphaImage> images_;
    std::vector<int> image_slot_;  // per scene image: its index in images_, -1 not copied yet
    std::vector<Triangle> triangles_;
};

// The BVH's triangles (SceneBvh::triangles, world space) in an Embree scene: one geometry per
// object over the object's segment, in the segment's order, so that Embree's hits name the very
// triangles the GLSL traversal would (triangle_of(geometry, primitive) is the index in
// bvh_triangles, where the shading code finds them). Embree's barycentrics (u, v) weigh v1 and
// v2, as the GLSL test's b1, b2 do. A dynamic scene (two levels inside Embree): update()
// rebuilds the moved objects' geometries and the top level only.
class EmbreeTracer {
public:
    // `masks`: the alpha test of alpha-tested triangles (an Embree filter function), kept by the
    // caller for the tracer's life and updated before update() is called.
    EmbreeTracer(const SceneBvh& bvh, const AlphaMasks* masks);
    ~EmbreeTracer();
    EmbreeTracer(const EmbreeTracer&) = delete;
    EmbreeTracer& operator=(const EmbreeTracer&) = delete;
    // The objects' triangles changed in `bvh` (moved, or their alpha test): their geometries again.
    void update(const SceneBvh& bvh, const std::vector<int>& objects);
    // Answers n queries on all cores (threads, each ray by itself: the reflection rays of rough
    // surfaces are incoherent, where Embree's single-ray kernel is its fastest).
    void trace(const TraceQuery* queries, size_t n, TraceAnswer* answers) const;
    // The RTCScene, for callers that trace their own rays (passes/reference_cpu.h).
    const void* scene() const { return scene_; }
    // The index in the BVH's triangles of a hit's (geometry, primitive).
    int32_t triangle_of(unsigned geometry, unsigned primitive) const {
        return int32_t(geometries_[geometry].first + primitive);
    }
    // Per geometry (the filter's user data): where its triangles start, and the masks.
    struct Geometry {
        size_t first = 0;
        const AlphaMasks* masks = nullptr;
    };

private:
    void fill(const SceneBvh& bvh, int object, bool attach);
    void* device_ = nullptr;  // RTCDevice
    void* scene_ = nullptr;   // RTCScene
    const AlphaMasks* masks_ = nullptr;
    std::vector<Geometry> geometries_;  // one per object, never resized after construction
};

}  // namespace ssr
