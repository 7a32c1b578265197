#include "scene/embree_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>

namespace ssr {

namespace {

// scene_textures.glsl's wrap_coordinate (glTF / GL wrap enums).
int wrap_coordinate(int i, int n, int mode) {
    auto floor_mod = [](int a, int m) { return a >= 0 ? a % m : (m - 1) - ((-(a + 1)) % m); };
    if (mode == 33071) return std::clamp(i, 0, n - 1);  // CLAMP_TO_EDGE
    if (mode == 33648) {                                // MIRRORED_REPEAT
        const int j = floor_mod(i, 2 * n);
        return j < n ? j : 2 * n - 1 - j;
    }
    return floor_mod(i, n);  // REPEAT
}

// Embree's filter for intersect and occluded queries alike: a hole's hit is rejected.
void alpha_filter(const RTCFilterFunctionNArguments* args) {
    const auto* geometry = static_cast<const EmbreeTracer::Geometry*>(args->geometryUserPtr);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        const size_t triangle = geometry->first + RTCHitN_primID(args->hit, args->N, i);
        if (geometry->masks->hole(triangle, RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i)))
            args->valid[i] = 0;
    }
}

}  // namespace

AlphaMasks::AlphaMasks(const Scene& scene, const std::vector<BvhTriangle>& triangles) {
    update(scene, triangles, 0, triangles.size());
}

void AlphaMasks::update(const Scene& scene, const std::vector<BvhTriangle>& triangles, size_t first, size_t count) {
    bool any = false;
    for (size_t i = first; i < first + count; ++i) any = any || triangles[i].alpha_tested;
    if (triangles_.empty()) {
        if (!any) return;  // no triangle tested so far: stays empty
        triangles_.resize(triangles.size());
    }
    if (image_slot_.size() != scene.images.size()) image_slot_.resize(scene.images.size(), -1);
    for (size_t i = first; i < first + count; ++i)
        triangles_[i] = triangles[i].alpha_tested ? triangle(scene, triangles[i]) : Triangle{};
}

AlphaMasks::Triangle AlphaMasks::triangle(const Scene& scene, const BvhTriangle& bt) {
    const Object& obj = scene.objects[size_t(bt.object)];
    const Material& m = scene.materials[size_t(obj.material)];
    const Mesh& mesh = scene.meshes[size_t(obj.mesh)];
    Triangle t;
    t.cutoff = m.visibility_cutoff();
    t.factor = m.base_color.a;
    if (!mesh.colors.empty())
        for (int k = 0; k < 3; ++k) t.vertex_alpha[k] = mesh.colors[mesh.indices[3 * size_t(bt.primitive) + size_t(k)]].a;
    const TextureRef& ref = m.base_color_texture;
    if (!ref.valid()) return t;
    int& slot = image_slot_[size_t(ref.image)];
    if (slot < 0) {  // each image's alpha copied once
        const Image& img = scene.images[size_t(ref.image)];
        AlphaImage a;
        a.width = img.width;
        a.height = img.height;
        a.alpha.resize(size_t(img.width) * size_t(img.height));
        for (size_t p = 0; p < a.alpha.size(); ++p) a.alpha[p] = img.rgba[4 * p + 3];
        slot = int(images_.size());
        images_.push_back(std::move(a));
    }
    t.image = slot;
    t.wrap_s = ref.wrap_s;
    t.wrap_t = ref.wrap_t;
    // Without texture coordinates the GPU reads uv (0, 0) (the vertex buffer's zero fill); a
    // texture on set 1 of a mesh without one reads set 0 (GpuScene's copy), as glTF falls back.
    const std::vector<glm::vec2>& set = ref.texcoord == 1 && !mesh.uvs1.empty() ? mesh.uvs1 : mesh.uvs;
    for (int k = 0; k < 3; ++k) {
        // The transform is affine: applied at the vertices, it interpolates as at the hit.
        const glm::vec2 uv =
            ref.apply(set.empty() ? glm::vec2(0.0f) : set[mesh.indices[3 * size_t(bt.primitive) + size_t(k)]]);
        t.uv[2 * k] = uv.x;
        t.uv[2 * k + 1] = uv.y;
    }
    return t;
}

bool AlphaMasks::hole(size_t triangle, float b1, float b2) const {
    if (triangle >= triangles_.size()) return false;
    const Triangle& t = triangles_[triangle];
    if (t.cutoff < 0.0f) return false;
    float alpha = t.factor;
    if (t.image >= 0) {
        const AlphaImage& img = images_[size_t(t.image)];
        const float b0 = 1.0f - b1 - b2;
        const float u = b0 * t.uv[0] + b1 * t.uv[2] + b2 * t.uv[4];
        const float v = b0 * t.uv[1] + b1 * t.uv[3] + b2 * t.uv[5];
        const float x = u * float(img.width) - 0.5f, y = v * float(img.height) - 0.5f;
        const float fx0 = std::floor(x), fy0 = std::floor(y);
        const float fx = x - fx0, fy = y - fy0;
        const int ix = int(fx0), iy = int(fy0);
        const int x0 = wrap_coordinate(ix, img.width, t.wrap_s), x1 = wrap_coordinate(ix + 1, img.width, t.wrap_s);
        const int y0 = wrap_coordinate(iy, img.height, t.wrap_t), y1 = wrap_coordinate(iy + 1, img.height, t.wrap_t);
        auto at = [&](int px, int py) { return float(img.alpha[size_t(py) * size_t(img.width) + size_t(px)]) / 255.0f; };
        const float top = at(x0, y0) + (at(x1, y0) - at(x0, y0)) * fx;
        const float bottom = at(x0, y1) + (at(x1, y1) - at(x0, y1)) * fx;
        alpha *= top + (bottom - top) * fy;
    }
    // COLOR_0's alpha interpolated as lib/scene_geometry.glsl does (exactly 1 without colours), the
    // last factor as in lib/bvh.glsl.
    const float* a = t.vertex_alpha;
    alpha *= a[0] + b1 * (a[1] - a[0]) + b2 * (a[2] - a[0]);
    return alpha < t.cutoff;
}

std::vector<CpuHit> embree_intersect(const Scene& scene, const std::vector<glm::vec3>& origins,
                                     const std::vector<glm::vec3>& directions, float t_min, float t_max) {
    if (origins.size() != directions.size()) throw std::invalid_argument("origins and directions differ in length");
    RTCDevice device = rtcNewDevice(nullptr);
    if (!device) throw std::runtime_error("Embree: rtcNewDevice failed");
    RTCScene rs = rtcNewScene(device);
    rtcSetSceneFlags(rs, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(rs, RTC_BUILD_QUALITY_HIGH);
    for (size_t o = 0; o < scene.objects.size(); ++o) {
        const Object& obj = scene.objects[o];
        const Mesh& mesh = scene.meshes[size_t(obj.mesh)];
        RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                              3 * sizeof(float), mesh.positions.size()));
        for (size_t i = 0; i < mesh.positions.size(); ++i) {
            const glm::vec3 w = glm::vec3(obj.transform * glm::vec4(mesh.positions[i], 1.0f));
            v[3 * i] = w.x;
            v[3 * i + 1] = w.y;
            v[3 * i + 2] = w.z;
        }
        auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(unsigned), mesh.triangle_count()));
        std::copy(mesh.indices.begin(), mesh.indices.end(), idx);
        rtcCommitGeometry(geom);
        rtcAttachGeometryByID(rs, geom, unsigned(o));  // geomID = object index
        rtcReleaseGeometry(geom);
    }
    rtcCommitScene(rs);

    std::vector<CpuHit> hits(origins.size());
    auto work = [&](size_t begin, size_t end) {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        for (size_t i = begin; i < end; ++i) {
            RTCRayHit rh{};
            rh.ray.org_x = origins[i].x;
            rh.ray.org_y = origins[i].y;
            rh.ray.org_z = origins[i].z;
            rh.ray.dir_x = directions[i].x;
            rh.ray.dir_y = directions[i].y;
            rh.ray.dir_z = directions[i].z;
            rh.ray.tnear = t_min;
            rh.ray.tfar = t_max;
            rh.ray.mask = 0xffffffffu;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(rs, &ctx, &rh);
            CpuHit& h = hits[i];
            if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
                h = CpuHit{std::numeric_limits<float>::infinity(), -1, -1, 0.0f, 0.0f};
            } else {
                h = CpuHit{rh.ray.tfar, int(rh.hit.geomID), int(rh.hit.primID), rh.hit.u, rh.hit.v};
            }
        }
    };
    const size_t threads = std::max(1u, std::thread::hardware_concurrency());
    std::vector<std::thread> pool;
    const size_t chunk = (origins.size() + threads - 1) / threads;
    for (size_t t = 0; t < threads; ++t) {
        const size_t b = t * chunk, e = std::min(origins.size(), b + chunk);
        if (b < e) pool.emplace_back(work, b, e);
    }
    for (auto& th : pool) th.join();
    rtcReleaseScene(rs);
    rtcReleaseDevice(device);
    return hits;
}

EmbreeTracer::EmbreeTracer(const SceneBvh& bvh, const AlphaMasks* masks) : masks_(masks) {
    RTCDevice device = rtcNewDevice(nullptr);
    if (!device) throw std::runtime_error("Embree: rtcNewDevice failed");
    device_ = device;
    RTCScene rs = rtcNewScene(device);
    scene_ = rs;
    // Robust: no traversal shortcuts that lose accuracy, so edges and corners are not missed
    // (the GLSL test is watertight, Woop et al. 2013). Dynamic with the scene's quality low:
    // Embree's two-level structure, a tree per geometry (each built at the geometry's quality,
    // high as before) and one over them, so a commit after a move rebuilds the moved objects'
    // trees and the top one only (a high-quality scene is one tree over every triangle, built
    // again whole at every commit).
    rtcSetSceneFlags(rs, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_DYNAMIC);
    rtcSetSceneBuildQuality(rs, RTC_BUILD_QUALITY_LOW);
    geometries_.resize(bvh.object_count());
    for (size_t o = 0; o < bvh.object_count(); ++o) fill(bvh, int(o), true);
    rtcCommitScene(rs);
    if (rtcGetDeviceError(device) != RTC_ERROR_NONE) {
        rtcReleaseScene(rs);
        rtcReleaseDevice(device);
        throw std::runtime_error("Embree: building the reference's scene failed");
    }
}

void EmbreeTracer::fill(const SceneBvh& bvh, int object, bool attach) {
    const size_t first = bvh.first_triangle(object), n = bvh.triangle_count(object);
    Geometry& g = geometries_[size_t(object)];
    g.first = first;
    g.masks = masks_;
    RTCGeometry geom = attach ? rtcNewGeometry(static_cast<RTCDevice>(device_), RTC_GEOMETRY_TYPE_TRIANGLE)
                              : rtcGetGeometry(static_cast<RTCScene>(scene_), unsigned(object));
    float* v = nullptr;
    if (attach) {
        v = static_cast<float*>(
            rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * n));
        auto* idx = static_cast<unsigned*>(
            rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), n));
        for (size_t i = 0; i < 3 * n; ++i) idx[i] = unsigned(i);
        rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_HIGH);
    } else {
        v = static_cast<float*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_VERTEX, 0));
    }
    bool alpha = false;
    for (size_t i = 0; i < n; ++i) {
        const BvhTriangle& t = bvh.triangles()[first + i];
        for (int k = 0; k < 3; ++k) {
            v[9 * i + k] = t.v0[k];
            v[9 * i + 3 + k] = t.v1[k];
            v[9 * i + 6 + k] = t.v2[k];
        }
        alpha = alpha || t.alpha_tested;
    }
    if (!attach) rtcUpdateGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0);
    const bool filter = alpha && masks_ && !masks_->empty();
    rtcSetGeometryUserData(geom, filter ? &g : nullptr);
    rtcSetGeometryIntersectFilterFunction(geom, filter ? alpha_filter : nullptr);
    rtcSetGeometryOccludedFilterFunction(geom, filter ? alpha_filter : nullptr);
    rtcCommitGeometry(geom);
    if (attach) {
        rtcAttachGeometryByID(static_cast<RTCScene>(scene_), geom, unsigned(object));  // geomID = object index
        rtcReleaseGeometry(geom);
    }
}

void EmbreeTracer::update(const SceneBvh& bvh, const std::vector<int>& objects) {
    if (objects.empty()) return;
    for (int o : objects) fill(bvh, o, false);
    rtcCommitScene(static_cast<RTCScene>(scene_));
    if (rtcGetDeviceError(static_cast<RTCDevice>(device_)) != RTC_ERROR_NONE)
        throw std::runtime_error("Embree: updating the reference's scene failed");
}

EmbreeTracer::~EmbreeTracer() {
    if (scene_) rtcReleaseScene(static_cast<RTCScene>(scene_));
    if (device_) rtcReleaseDevice(static_cast<RTCDevice>(device_));
}

void EmbreeTracer::trace(const TraceQuery* queries, size_t n, TraceAnswer* answers) const {
    RTCScene rs = static_cast<RTCScene>(scene_);
    constexpr size_t kBlock = 256;
    std::atomic<size_t> next{0};
    auto finite = [](const float* a) { return std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]); };
    auto work = [&]() {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        for (;;) {
            const size_t begin = next.fetch_add(kBlock);
            if (begin >= n) break;
            const size_t end = std::min(n, begin + kBlock);
            for (size_t i = begin; i < end; ++i) {
                const TraceQuery& q = queries[i];
                TraceAnswer& a = answers[i];
                a = TraceAnswer{q.t_max, -1, 0.0f, 0.0f};
                // Embree asserts on NaN or infinite rays; the GLSL traversal misses them.
                if (q.kind == 0 || !finite(q.origin) || !finite(q.dir) || !(q.t_max >= q.t_min)) continue;
                RTCRayHit rh;
                rh.ray.org_x = q.origin[0];
                rh.ray.org_y = q.origin[1];
                rh.ray.org_z = q.origin[2];
                rh.ray.dir_x = q.dir[0];
                rh.ray.dir_y = q.dir[1];
                rh.ray.dir_z = q.dir[2];
                rh.ray.tnear = q.t_min;
                rh.ray.tfar = q.t_max;
                rh.ray.time = 0.0f;
                rh.ray.mask = 0xffffffffu;
                rh.ray.id = 0;
                rh.ray.flags = 0;
                if (q.kind == 2) {
                    rtcOccluded1(rs, &ctx, &rh.ray);
                    if (rh.ray.tfar < 0.0f) a.triangle = 0;  // occluded: any triangle will do
                    continue;
                }
                rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
                rtcIntersect1(rs, &ctx, &rh);
                if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
                a = TraceAnswer{rh.ray.tfar, triangle_of(rh.hit.geomID, rh.hit.primID), rh.hit.u, rh.hit.v};
            }
        }
    };
    const size_t threads = std::min<size_t>(std::max(1u, std::thread::hardware_concurrency()), (n + kBlock - 1) / kBlock);
    if (threads <= 1) {
        work();
        return;
    }
    std::vector<std::thread> pool;
    for (size_t t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    for (auto& th : pool) th.join();
}

}  // namespace ssr
