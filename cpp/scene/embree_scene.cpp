#include "scene/embree_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <thread>

namespace ssr {

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

}  // namespace ssr
