#include "passes/reference_cpu.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <thread>
#if defined(__SSE__) || defined(_M_X64)
#include <xmmintrin.h>
#define SSR_HAVE_MXCSR 1
#endif

namespace ssr {

// Each function below names the GLSL it mirrors; keep the two in step (the agreement test,
// tests/test_reference_cpu.py, compares them per pixel on every procedural scene).
namespace {

using glm::ivec2;
using glm::mat3;
using glm::vec2;
using glm::vec3;
using glm::vec4;

constexpr float PI = 3.14159265358979f;  // lib/brdf.glsl
constexpr int SAMPLING_MIRROR = 0, SAMPLING_VNDF = 2, SAMPLING_GGX_THESIS_LITERAL = 3;
constexpr float kFar = 3.4e38f;

inline int float_bits(float f) {
    int i;
    std::memcpy(&i, &f, 4);
    return i;
}
inline float bits_float(int i) {
    float f;
    std::memcpy(&f, &i, 4);
    return f;
}
inline float clampf(float x, float lo, float hi) { return std::min(std::max(x, lo), hi); }
inline float fract(float x) { return x - std::floor(x); }
inline float inversesqrt(float x) { return 1.0f / std::sqrt(x); }

// ---- lib/random.glsl ----
inline uint32_t pcg_hash(uint32_t v) {
    const uint32_t state = v * 747796405u + 2891336453u;
    const uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}
inline float unit_float(uint32_t x) { return float(x >> 8u) * (1.0f / 16777216.0f); }
inline uint32_t bitfield_reverse(uint32_t v) {
    v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
    v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
    v = ((v >> 4) & 0x0F0F0F0Fu) | ((v & 0x0F0F0F0Fu) << 4);
    v = ((v >> 8) & 0x00FF00FFu) | ((v & 0x00FF00FFu) << 8);
    return (v >> 16) | (v << 16);
}
inline vec2 hammersley(uint32_t i, uint32_t n) {
    return vec2(float(i) / float(n), float(bitfield_reverse(i)) * 2.3283064365386963e-10f);
}

// ---- lib/brdf.glsl ----
inline float ggx_D(float NoH, float alpha) {
    const float a2 = alpha * alpha;
    const float d = NoH * NoH * (a2 - 1.0f) + 1.0f;
    return a2 / std::max(PI * d * d, 1e-12f);
}
inline float ggx_G1(float NoV, float alpha) {
    const float c2 = std::max(NoV * NoV, 1e-8f);
    const float tan2 = std::max(1.0f - c2, 0.0f) / c2;
    return 2.0f / (1.0f + std::sqrt(1.0f + alpha * alpha * tan2));
}
inline float ggx_G(float NoL, float NoV, float alpha) { return ggx_G1(NoL, alpha) * ggx_G1(NoV, alpha); }
inline vec3 fresnel_schlick(vec3 F0, float cos_theta) {
    const float f = std::pow(clampf(1.0f - cos_theta, 0.0f, 1.0f), 5.0f);
    return F0 + (1.0f - F0) * f;
}
inline float ggx_alpha(float perceptual_roughness) {
    const float r = std::max(perceptual_roughness, 0.03f);
    return r * r;
}

// ---- lib/ggx_sampling.glsl ----
struct BrdfSample {
    vec3 l;
    float weight, pdf;
};
inline mat3 frame_from_normal(vec3 n) {
    const float s = n.z >= 0.0f ? 1.0f : -1.0f;
    const float a = -1.0f / (s + n.z);
    const float b = n.x * n.y * a;
    return mat3(vec3(1.0f + s * n.x * n.x * a, s * b, -s * n.x), vec3(b, s + n.y * n.y * a, -n.y), n);
}
inline vec3 sample_ggx_normal(vec2 u, float alpha) {
    const float tan2 = alpha * alpha * u.x / std::max(1.0f - u.x, 1e-7f);
    const float cos_theta = inversesqrt(1.0f + tan2);
    const float sin_theta = std::sqrt(std::max(1.0f - cos_theta * cos_theta, 0.0f));
    const float phi = 2.0f * PI * u.y;
    return vec3(std::cos(phi) * sin_theta, std::sin(phi) * sin_theta, cos_theta);
}
inline vec3 sample_ggx_normal_thesis_literal(vec2 u, float alpha) {
    const vec3 m = sample_ggx_normal(u, alpha);
    return glm::normalize(vec3(m.x, m.y, 1.0f + (1.0f - m.z)));
}
inline vec3 sample_vndf(vec3 v, float alpha, vec2 u) {
    const vec3 vh = glm::normalize(vec3(alpha * v.x, alpha * v.y, v.z));
    const float len2 = vh.x * vh.x + vh.y * vh.y;
    const vec3 t1 = len2 > 0.0f ? vec3(-vh.y, vh.x, 0.0f) * inversesqrt(len2) : vec3(1.0f, 0.0f, 0.0f);
    const vec3 t2 = glm::cross(vh, t1);
    const float r = std::sqrt(u.x);
    const float phi = 2.0f * PI * u.y;
    const float p1 = r * std::cos(phi);
    float p2 = r * std::sin(phi);
    const float s = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - s) * std::sqrt(std::max(1.0f - p1 * p1, 0.0f)) + s * p2;
    const vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(1.0f - p1 * p1 - p2 * p2, 0.0f)) * vh;
    return glm::normalize(vec3(alpha * nh.x, alpha * nh.y, std::max(nh.z, 0.0f)));
}
inline BrdfSample sample_reflection(vec3 v, float alpha, int method, vec2 u) {
    BrdfSample s;
    if (method == SAMPLING_MIRROR || alpha < 1e-4f) {
        s.l = vec3(-v.x, -v.y, v.z);
        s.weight = 1.0f;
        s.pdf = 0.0f;
        return s;
    }
    const vec3 m = method == SAMPLING_VNDF                ? sample_vndf(v, alpha, u)
                   : method == SAMPLING_GGX_THESIS_LITERAL ? sample_ggx_normal_thesis_literal(u, alpha)
                                                           : sample_ggx_normal(u, alpha);
    const float vm = glm::dot(v, m);
    s.l = 2.0f * vm * m - v;
    const float nl = s.l.z, nv = v.z, nm = m.z;
    if (nl <= 0.0f || vm <= 0.0f || nm <= 0.0f) {
        s.weight = 0.0f;
        s.pdf = 0.0f;
        return s;
    }
    const float D = ggx_D(nm, alpha);
    if (method == SAMPLING_VNDF) {
        s.pdf = ggx_G1(nv, alpha) * D / (4.0f * nv);
        s.weight = ggx_G1(nl, alpha);
    } else {
        s.pdf = D * nm / (4.0f * vm);
        s.weight = vm * ggx_G(nl, nv, alpha) / (nv * nm);
    }
    return s;
}

// ---- lib/gbuffer.glsl ----
struct GSample {
    vec3 albedo;
    float metallic;
    vec3 normal;
    float roughness;
    float reflectivity;
    bool covered;
    int object_id;
};

// ---- lib/normal_mapping.glsl ----
inline bool tangent_frame_from_vertex(vec3 n, vec4 tangent, glm::mat2 uv_linear, vec3& t, vec3& b) {
    t = vec3(1.0f, 0.0f, 0.0f);
    b = vec3(0.0f, 1.0f, 0.0f);
    const vec3 t3(tangent);
    if (glm::dot(t3, t3) <= 1e-12f || tangent.w == 0.0f) return false;
    t = glm::normalize(t3 - n * glm::dot(n, t3));
    b = glm::cross(n, t) * tangent.w;
    const float det = glm::determinant(uv_linear);
    if (uv_linear != glm::mat2(1.0f) && std::abs(det) > 1e-12f) {
        const glm::mat2 inv = glm::inverse(uv_linear);
        const vec3 tu = t * inv[0][0] + b * inv[0][1], tv = t * inv[1][0] + b * inv[1][1];
        t = glm::normalize(tu);
        b = glm::normalize(tv);
    }
    return true;
}

// ---- lib/scene_data.glsl ----
inline vec2 texture_uv(const GpuMaterial& m, int k, vec2 uv) {
    return vec2(glm::dot(vec3(m.uv_transform[2 * k]), vec3(uv, 1.0f)),
                glm::dot(vec3(m.uv_transform[2 * k + 1]), vec3(uv, 1.0f)));
}
inline vec2 texture_set(const GpuMaterial& m, int k, vec4 uvs) {
    return m.uv_transform[2 * k].w != 0.0f ? vec2(uvs.z, uvs.w) : vec2(uvs.x, uvs.y);
}
inline vec2 texture_uv(const GpuMaterial& m, int k, vec4 uvs) { return texture_uv(m, k, texture_set(m, k, uvs)); }
inline glm::mat2 texture_linear(const GpuMaterial& m, int k) {
    return glm::mat2(m.uv_transform[2 * k].x, m.uv_transform[2 * k + 1].x, m.uv_transform[2 * k].y,
                     m.uv_transform[2 * k + 1].y);
}
inline bool tangent_frame_from_gradients(vec3 n, vec3 dp1, vec3 dp2, vec2 duv1, vec2 duv2, vec3& t, vec3& b) {
    const vec3 dp2perp = glm::cross(dp2, n), dp1perp = glm::cross(n, dp1);
    t = dp2perp * duv1.x + dp1perp * duv2.x;
    b = dp2perp * duv1.y + dp1perp * duv2.y;
    const float scale = std::max(glm::dot(t, t), glm::dot(b, b));
    if (scale < 1e-20f) return false;
    const float inv = inversesqrt(scale);
    t *= inv;
    b *= inv;
    return true;
}
inline vec3 apply_normal_map(vec3 n, vec3 t, vec3 b, vec3 tangent_space_normal) {
    const vec3 result = mat3(t, b, n) * tangent_space_normal;
    const float len = glm::length(result);
    return len > 1e-8f ? result / len : n;
}

// ---- lib/ray_offset.glsl ----
inline vec3 offset_ray_origin(vec3 p, vec3 n) {
    constexpr float kOrigin = 1.0f / 32.0f, kFloatScale = 1.0f / 65536.0f, kIntScale = 256.0f;
    vec3 r;
    for (int k = 0; k < 3; ++k) {
        const int of = int(kIntScale * n[k]);
        const float pi = bits_float(float_bits(p[k]) + (p[k] < 0.0f ? -of : of));
        r[k] = std::abs(p[k]) < kOrigin ? p[k] + kFloatScale * n[k] : pi;
    }
    return r;
}

// ---- lib/scene_textures.glsl ----
constexpr int WRAP_CLAMP = 33071, WRAP_MIRRORED = 33648;
inline int floor_mod(int i, int n) { return i >= 0 ? i % n : (n - 1) - ((-(i + 1)) % n); }
inline int wrap_coordinate(int i, int n, int mode) {
    if (mode == WRAP_CLAMP) return std::clamp(i, 0, n - 1);
    if (mode == WRAP_MIRRORED) {
        const int period = 2 * n;
        const int j = floor_mod(i, period);
        return j < n ? j : period - 1 - j;
    }
    return floor_mod(i, n);
}
inline float srgb_channel(float c) {
    return c < 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

struct Hit {
    float t;
    int triangle;  // -1: miss
    float b1, b2;
};

struct ShadedHit {
    bool hit;
    vec3 radiance;
};

// One worker's view of the scene: the Embree queries and the shading (what one GLSL invocation
// computes per ray).
class Shader {
public:
    explicit Shader(const CpuReferenceScene& s)
        : s_(s), scene_(static_cast<RTCScene>(const_cast<void*>(s.tracer->scene()))) {
        rtcInitIntersectContext(&ctx_);
        view3_ = mat3(s.frame.view);
        inv_view3_ = mat3(s.frame.inv_view);
    }
    uint64_t rays = 0;

    static bool finite(vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

    // lib/bvh.glsl's trace_closest through Embree, as EmbreeTracer::trace answers it.
    Hit trace_closest(vec3 o, vec3 d, float t_min, float t_max) {
        Hit h{t_max, -1, 0.0f, 0.0f};
        if (!finite(o) || !finite(d) || !(t_max >= t_min)) return h;  // Embree asserts; the GLSL misses
        RTCRayHit rh;
        rh.ray.org_x = o.x;
        rh.ray.org_y = o.y;
        rh.ray.org_z = o.z;
        rh.ray.dir_x = d.x;
        rh.ray.dir_y = d.y;
        rh.ray.dir_z = d.z;
        rh.ray.tnear = t_min;
        rh.ray.tfar = t_max;
        rh.ray.time = 0.0f;
        rh.ray.mask = 0xffffffffu;
        rh.ray.id = 0;
        rh.ray.flags = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene_, &ctx_, &rh);
        ++rays;
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
        return Hit{rh.ray.tfar, s_.tracer->triangle_of(rh.hit.geomID, rh.hit.primID), rh.hit.u, rh.hit.v};
    }
    bool trace_occluded(vec3 o, vec3 d, float t_min, float t_max) {
        if (!finite(o) || !finite(d) || !(t_max >= t_min)) return false;
        RTCRay r;
        r.org_x = o.x;
        r.org_y = o.y;
        r.org_z = o.z;
        r.dir_x = d.x;
        r.dir_y = d.y;
        r.dir_z = d.z;
        r.tnear = t_min;
        r.tfar = t_max;
        r.time = 0.0f;
        r.mask = 0xffffffffu;
        r.id = 0;
        r.flags = 0;
        rtcOccluded1(scene_, &ctx_, &r);
        ++rays;
        return r.tfar < 0.0f;
    }

    // lib/trace_shade.glsl
    vec3 hit_point_w(const Hit& h) const {
        const BvhTriangle& tri = s_.triangles[size_t(h.triangle)];
        return vec3(tri.v0[0], tri.v0[1], tri.v0[2]) * (1.0f - h.b1 - h.b2) + vec3(tri.v1[0], tri.v1[1], tri.v1[2]) * h.b1 +
               vec3(tri.v2[0], tri.v2[1], tri.v2[2]) * h.b2;
    }
    vec3 hit_normal_w(const Hit& h, vec3 toward) const {
        const BvhTriangle& tri = s_.triangles[size_t(h.triangle)];
        const vec3 v0(tri.v0[0], tri.v0[1], tri.v0[2]), v1(tri.v1[0], tri.v1[1], tri.v1[2]),
            v2(tri.v2[0], tri.v2[1], tri.v2[2]);
        const vec3 n = glm::normalize(glm::cross(v1 - v0, v2 - v0));
        return glm::dot(n, toward) >= 0.0f ? n : -n;
    }

    // lib/environment.glsl
    vec3 sky_gradient(float y) const {
        const FrameUniforms& f = s_.frame;
        y = clampf(y, -1.0f, 1.0f);
        return y >= 0.0f ? glm::mix(vec3(f.env_horizon), vec3(f.env_zenith), std::sqrt(y))
                         : glm::mix(vec3(f.env_horizon), vec3(f.env_ground), std::sqrt(std::min(-y * 4.0f, 1.0f)));
    }
    vec3 environment_radiance(vec3 dir) const {
        const FrameUniforms& f = s_.frame;
        if (s_.environment_type == 0) return vec3(f.env_color) * f.env_params.y;
        if (s_.environment_type == 1) return sky_gradient(dir.y) * f.env_params.y;
        const int type = int(f.env_params.x);
        vec3 c = vec3(f.env_color);
        if (type == 1) {
            c = sky_gradient(dir.y);
        } else if (type == 2 && s_.environment_width > 0) {
            const float u = 0.5f + std::atan2(dir.x, -dir.z) / (2.0f * PI);
            const float v = std::acos(clampf(dir.y, -1.0f, 1.0f)) / PI;
            c = environment_texel(u, v);
        }
        return c * f.env_params.y;
    }
    // textureLod(level 0) of the map: bilinear, wrap s repeat, wrap t clamp to edge (GpuScene).
    vec3 environment_texel(float u, float v) const {
        const int w = s_.environment_width, h = s_.environment_height;
        const float x = u * float(w) - 0.5f, y = v * float(h) - 0.5f;
        const float fx0 = std::floor(x), fy0 = std::floor(y);
        const int i0 = int(fx0), j0 = int(fy0);
        const float fx = x - fx0, fy = y - fy0;
        const int xa = floor_mod(i0, w), xb = floor_mod(i0 + 1, w);
        const int ya = std::clamp(j0, 0, h - 1), yb = std::clamp(j0 + 1, 0, h - 1);
        auto at = [&](int xi, int yi) { return vec3(s_.environment_map[size_t(yi) * size_t(w) + size_t(xi)]); };
        const vec3 top = glm::mix(at(xa, ya), at(xb, ya), fx);
        const vec3 bottom = glm::mix(at(xa, yb), at(xb, yb), fx);
        return glm::mix(top, bottom, fy);
    }

    // lib/scene_textures.glsl
    vec4 image_texel(int image, int x, int y, bool srgb) const {
        const glm::ivec4 info = s_.image_info[size_t(image)];
        const uint32_t t = s_.image_texels[size_t(info.x + y * info.y + x)];
        vec4 v(float(t & 255u) / 255.0f, float((t >> 8) & 255u) / 255.0f, float((t >> 16) & 255u) / 255.0f,
               float(t >> 24) / 255.0f);
        if (srgb) v = vec4(srgb_channel(v.x), srgb_channel(v.y), srgb_channel(v.z), v.w);
        return v;
    }
    vec4 sample_image(int image, vec2 uv, int wraps, bool srgb) const {
        if (image < 0) return vec4(1.0f);
        const glm::ivec4 info = s_.image_info[size_t(image)];
        const int ws = wraps & 0xffff, wt = wraps >> 16;
        const vec2 x = uv * vec2(float(info.y), float(info.z)) - 0.5f;
        const ivec2 i0(int(std::floor(x.x)), int(std::floor(x.y)));
        const vec2 f = x - vec2(i0);
        const int x0 = wrap_coordinate(i0.x, info.y, ws), x1 = wrap_coordinate(i0.x + 1, info.y, ws);
        const int y0 = wrap_coordinate(i0.y, info.z, wt), y1 = wrap_coordinate(i0.y + 1, info.z, wt);
        const vec4 top = glm::mix(image_texel(image, x0, y0, srgb), image_texel(image, x1, y0, srgb), f.x);
        const vec4 bottom = glm::mix(image_texel(image, x0, y1, srgb), image_texel(image, x1, y1, srgb), f.x);
        return glm::mix(top, bottom, f.y);
    }

    // lib/shading.glsl with trace_shade.glsl's TRACED_SHADOWS light_visibility; surface_point_w
    // and surface_normal_w are the shaded point's (what its shadow rays leave from).
    // dielectric: the non-metal part's F0 (KHR_materials_ior and _specular; 0.04 at their defaults).
    vec3 shade_surface(const GSample& g, vec3 emission, vec3 dielectric, vec3 p, vec3 v, vec3 surface_point_w,
                       vec3 surface_normal_w) {
        const vec3 n = g.normal;
        const float NoV = std::max(glm::dot(n, v), 1e-4f);
        const float alpha = ggx_alpha(g.roughness);
        const vec3 F0 = glm::mix(dielectric, g.albedo, g.metallic);
        const vec3 diffuse_color = g.albedo * (1.0f - g.metallic);
        vec3 radiance = vec3(s_.frame.ambient) * g.albedo;
        radiance += emission;
        for (const GpuLight& light : s_.lights) {
            vec3 l;
            vec3 irradiance = vec3(light.radiance);
            float light_distance = kFar;
            if (light.position_type.w == 0.0f) {
                l = -glm::normalize(vec3(light.direction_shadow));
            } else {
                const vec3 to_light = vec3(light.position_type) - p;
                const float d2 = std::max(glm::dot(to_light, to_light), 1e-8f);
                l = to_light * inversesqrt(d2);
                light_distance = std::sqrt(d2);
                irradiance /= d2;
                const float w = clampf(1.0f - d2 * d2 * light.cone.z * light.cone.z, 0.0f, 1.0f);
                float spot = 1.0f;
                if (light.position_type.w == 2.0f)
                    spot = clampf(glm::dot(glm::normalize(vec3(light.direction_shadow)), -l) * light.cone.x + light.cone.y,
                                  0.0f, 1.0f);
                irradiance *= w * w * spot * spot;
            }
            const float NoL = glm::dot(n, l);
            if (NoL <= 0.0f) continue;
            float visibility = 1.0f;
            if (light.direction_shadow.w > 0.5f) {
                const vec3 l_w = glm::normalize(inv_view3_ * l);
                if (glm::dot(surface_normal_w, l_w) <= 0.0f)
                    visibility = 0.0f;
                else
                    visibility = trace_occluded(offset_ray_origin(surface_point_w, surface_normal_w), l_w, 0.0f,
                                                light_distance)
                                     ? 0.0f
                                     : 1.0f;
            }
            if (visibility <= 0.0f) continue;
            irradiance *= visibility;
            const vec3 h = glm::normalize(l + v);
            const float NoH = std::max(glm::dot(n, h), 0.0f);
            const float VoH = std::max(glm::dot(v, h), 0.0f);
            const vec3 F = fresnel_schlick(F0, VoH);
            const vec3 specular = F * (ggx_D(NoH, alpha) * ggx_G(NoL, NoV, alpha) / (4.0f * NoL * NoV));
            const vec3 diffuse = (1.0f - F) * diffuse_color / PI;
            radiance += (diffuse + specular) * irradiance * NoL;
        }
        return radiance;
    }

    // lib/trace_shade.glsl's trace_and_shade_w, with lib/scene_geometry.glsl and lib/material.glsl.
    ShadedHit trace_and_shade_w(vec3 origin_w, vec3 dir_w, bool viewer_is_ray) {
        return shade_hit(trace_closest(origin_w, dir_w, 0.0f, s_.ssr.max_distance), dir_w, viewer_is_ray);
    }

    // A round's closest-hit rays from one origin, one by one: Embree's stream and packet
    // interfaces (rtcIntersect1M with the coherent flag, for these rays and for the shadow rays)
    // took 10-20 % more CPU time than single rays (the cross-check at 160x90/64, `perf stat -e
    // task-clock`, three runs each): 8 rays of a GGX lobe are too few and too divergent to share
    // a traversal.
    void trace_closest_n(vec3 o, const vec3* dirs, const bool* active, int n, float t_max, Hit* hits) {
        for (int k = 0; k < n; ++k)
            hits[k] = active[k] ? trace_closest(o, dirs[k], 0.0f, t_max) : Hit{t_max, -1, 0.0f, 0.0f};
    }

    ShadedHit shade_hit(const Hit& h, vec3 dir_w, bool viewer_is_ray) {
        ShadedHit s;
        s.hit = h.triangle >= 0;
        if (!s.hit) {
            s.radiance = environment_radiance(dir_w);
            return s;
        }
        const vec3 point_w = hit_point_w(h);
        const vec3 normal_w = hit_normal_w(h, -dir_w);
        const vec3 position = vec3(s_.frame.view * vec4(point_w, 1.0f));
        const BvhTriangle& tri = s_.triangles[size_t(h.triangle)];
        const int object = tri.object;
        const GpuObject& o = s_.objects[size_t(object)];
        const GpuMaterial& m = s_.materials[size_t(o.material.x)];
        // triangle_attributes
        const float b0 = 1.0f - h.b1 - h.b2;
        vec3 an(0.0f);
        vec4 at(0.0f);
        vec4 auv(0.0f);  // xy TEXCOORD_0, zw TEXCOORD_1
        vec4 vcolor[3];
        vec3 p[3];
        vec4 uvs[3];
        for (int k = 0; k < 3; ++k) {
            const uint32_t vi = s_.index_data[size_t(uint32_t(o.material.y) + uint32_t(3 * tri.primitive + k))] +
                                uint32_t(o.material.z);
            const float* f = s_.vertex_data.data() + size_t(vi) * kVertexFloats;
            p[k] = vec3(f[0], f[1], f[2]);
            const vec3 vn(f[3], f[4], f[5]);
            uvs[k] = vec4(f[6], f[7], f[16], f[17]);
            const vec4 vt(f[8], f[9], f[10], f[11]);
            const vec4 vc(f[12], f[13], f[14], f[15]);
            const float w = k == 0 ? b0 : (k == 1 ? h.b1 : h.b2);
            an += w * vn;
            auv += w * uvs[k];
            at += w * vt;
            vcolor[k] = vc;
        }
        const vec4 acolor = vcolor[0] + h.b1 * (vcolor[1] - vcolor[0]) + h.b2 * (vcolor[2] - vcolor[0]);
        const vec4 tangent(vec3(at), at.w >= 0.0f ? (at.w > 0.0f ? 1.0f : 0.0f) : -1.0f);
        const mat3 model_view = view3_ * mat3(o.model);
        vec3 n = glm::normalize(view3_ * (mat3(o.normal_matrix) * an));
        const vec3 face = glm::cross(model_view * (p[1] - p[0]), model_view * (p[2] - p[0]));
        const bool front_facing = glm::dot(face, -position) > 0.0f;
        vec3 t(0.0f), b(0.0f);
        bool has_frame = false;
        if (m.flags.z != 0) {
            has_frame =
                tangent_frame_from_vertex(n, vec4(model_view * vec3(tangent), tangent.w), texture_linear(m, 2), t, b) ||
                tangent_frame_from_gradients(n, model_view * (p[1] - p[0]), model_view * (p[2] - p[0]),
                                             texture_uv(m, 2, uvs[1]) - texture_uv(m, 2, uvs[0]),
                                             texture_uv(m, 2, uvs[2]) - texture_uv(m, 2, uvs[0]), t, b);
        }
        // material_sample: each texture at its own coordinates (KHR_texture_transform)
        const vec4 base_texel = sample_image(m.images.x, texture_uv(m, 0, auv), m.wraps.x, true);
        const vec4 mr_texel = sample_image(m.images.y, texture_uv(m, 1, auv), m.wraps.y, false);
        const vec3 normal_texel = vec3(sample_image(m.images.z, texture_uv(m, 2, auv), m.wraps.z, false));
        vec4 base = m.base_color;
        if (m.flags.x != 0) base *= base_texel;
        float metallic = m.params.x, roughness = m.params.y;
        if (m.flags.y != 0) {
            roughness *= mr_texel.y;
            metallic *= mr_texel.z;
        }
        if (!front_facing && m.flags.w != 0) {
            n = -n;
            b = -b;
        }
        if (m.flags.z != 0 && has_frame) {
            vec3 tn = normal_texel * 2.0f - 1.0f;
            tn.x *= m.params.w;
            tn.y *= m.params.w;
            n = apply_normal_map(n, t, b, glm::normalize(tn));
        }
        GSample g;
        g.albedo = vec3(base);
        g.albedo *= vec3(acolor);  // glTF COLOR_0 (trace_shade.glsl)
        g.metallic = clampf(metallic, 0.0f, 1.0f);
        g.normal = n;
        g.roughness = clampf(roughness, 0.0f, 1.0f);
        g.reflectivity = clampf(m.params.z, 0.0f, 1.0f);
        g.covered = true;
        g.object_id = object;
        // lib/material.glsl's material_emission, the emissive texture at its own coordinates
        // (KHR_texture_transform).
        vec3 emission = vec3(m.emissive);
        if (m.images.w >= 0) emission *= vec3(sample_image(m.images.w, texture_uv(m, 3, auv), m.wraps.w, true));
        const vec3 viewer = !viewer_is_ray ? glm::normalize(-position) : -glm::normalize(view3_ * dir_w);
        // lib/material.glsl's material_dielectric_f0, KHR_materials_specular's textures at their
        // own coordinates (rows 8..11), the factors' value without them.
        vec3 dielectric = vec3(m.dielectric_f0);
        if (m.specular_images.x >= 0 || m.specular_images.y >= 0) {
            vec3 color = vec3(m.specular_f0);
            if (m.specular_images.y >= 0)
                color *= vec3(sample_image(m.specular_images.y, texture_uv(m, 5, auv), m.specular_wraps.y, true));
            float specular = m.specular_f0.w;
            if (m.specular_images.x >= 0)
                specular *= sample_image(m.specular_images.x, texture_uv(m, 4, auv), m.specular_wraps.x, false).w;
            dielectric = glm::min(color, vec3(1.0f)) * specular;
        }
        s.radiance = shade_surface(g, emission, dielectric, position, viewer, point_w, normal_w);
        return s;
    }

    const CpuReferenceScene& s_;
    RTCScene scene_;
    RTCIntersectContext ctx_;
    mat3 view3_, inv_view3_;
};

// lib/depth_convention.glsl
inline vec3 view_position(const FrameUniforms& f, vec2 pixel, float z) {
    const vec2 ndc = pixel * vec2(f.viewport.z, f.viewport.w) * 2.0f - 1.0f;
    const vec2 xy = (ndc + vec2(f.proj[2][0], f.proj[2][1])) * z / vec2(f.proj[0][0], f.proj[1][1]);
    return vec3(xy, -z);
}

GSample decode(const CpuGbufferTexel& t) {
    GSample g;
    g.albedo = vec3(t.albedo_metallic);
    g.metallic = t.albedo_metallic.w;
    g.normal = vec3(t.normal_roughness);
    g.roughness = t.normal_roughness.w;
    g.reflectivity = t.material.x;
    g.covered = t.material.y > 0.5f;
    g.object_id = int(std::lround(t.material.z));
    return g;
}

}  // namespace

CpuReference::CpuReference(const CpuReferenceScene& scene, int width, int height, std::vector<CpuGbufferTexel> gbuffer,
                           std::vector<glm::vec4> emission, std::vector<glm::vec4> dielectric_f0)
    : s_(scene), width_(width), height_(height), gbuffer_(std::move(gbuffer)), emission_(std::move(emission)),
      dielectric_f0_(std::move(dielectric_f0)) {
    const size_t n = size_t(width) * size_t(height);
    state_.resize(n);
    accum_.assign(n, vec4(0.0f));
    reflection_.assign(n, vec4(0.0f, 0.0f, 0.0f, 1.0f));
    direct_.assign(n, vec4(0.0f, 0.0f, 0.0f, 1.0f));
}

// Rows handed out one at a time to one thread per core: rows differ in cost (mirror, rough,
// background), so a shared counter balances them. Each pixel's sums are added in ray order by
// one thread, so the result does not depend on the schedule.
// Denormals flush to zero on the workers (the caller's mode restored after): llvmpipe runs its
// shaders so (GLSL 4.50 4.7.1 lets denormals flush), so this matches the GLSL closer, and an x86
// core takes a microcode assist on every denormal operand (the tiny floors of ggx_D and
// friends) that costs as much as a hundred ordinary operations.
void CpuReference::parallel_rows(const std::function<void(int)>& row) {
    std::atomic<int> next{0};
    auto work = [&]() {
#if SSR_HAVE_MXCSR
        const unsigned saved = _mm_getcsr();
        _mm_setcsr(saved | 0x8040u);  // FTZ (bit 15) and DAZ (bit 6)
#endif
        for (;;) {
            const int y = next.fetch_add(1);
            if (y >= height_) break;
            row(y);
        }
#if SSR_HAVE_MXCSR
        _mm_setcsr(saved);
#endif
    };
    const int threads = std::max(1, std::min(int(std::thread::hardware_concurrency()), height_));
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    for (auto& th : pool) th.join();
}

// reference.comp's pixel set-up: the camera ray through the pixel centre finds the exact point.
void CpuReference::begin() {
    const FrameUniforms& f = s_.frame;
    parallel_rows([&](int y) {
        Shader sh(s_);
        const vec3 camera_w = vec3(f.inv_view[3]);
        for (int x = 0; x < width_; ++x) {
            const size_t i = size_t(y) * size_t(width_) + size_t(x);
            const GSample g = decode(gbuffer_[i]);
            PixelState& st = state_[i];
            const vec2 pc = vec2(float(x), float(y)) + 0.5f;
            st.pos = view_position(f, pc, gbuffer_[i].material.w);
            const vec3 pixel_dir_w = glm::normalize(sh.inv_view3_ * glm::normalize(view_position(f, pc, 1.0f)));
            const Hit primary = sh.trace_closest(camera_w, pixel_dir_w, 0.0f, kFar);
            st.exact = g.covered && primary.triangle >= 0 && s_.triangles[size_t(primary.triangle)].object == g.object_id;
            if (st.exact) {
                st.point_w = sh.hit_point_w(primary);
                st.normal_w = sh.hit_normal_w(primary, -pixel_dir_w);
                st.pos = vec3(f.view * vec4(st.point_w, 1.0f));
                st.origin_w = offset_ray_origin(st.point_w, st.normal_w);
            }
        }
        rays_ += sh.rays;
    });
}

// reference.comp's loop over ray indices, with lib/ray_generation.glsl's generate_ray.
void CpuReference::trace_rays(int first, int count) {
    const FrameUniforms& f = s_.frame;
    const SsrUniforms& su = s_.ssr;
    const uint32_t seed_hash = pcg_hash(su.seed);
    parallel_rows([&](int y) {
        Shader sh(s_);
        for (int x = 0; x < width_; ++x) {
            const size_t i = size_t(y) * size_t(width_) + size_t(x);
            const GSample g = decode(gbuffer_[i]);
            // is_reflective (the converged reference uploads roughness_cutoff 1)
            if (!(g.covered && g.reflectivity > 0.0f && g.roughness <= su.roughness_cutoff)) continue;
            const bool mirror = g.roughness * g.roughness < 1e-4f || su.sampling == SAMPLING_MIRROR;
            const PixelState& st = state_[i];
            const vec3 p_view = st.pos;
            const vec3 v = glm::normalize(-p_view);
            const vec3 n = g.normal;
            if (glm::dot(n, v) <= 1e-4f) continue;  // generate_ray: weight 0 for every r
            const mat3 tbn = frame_from_normal(n);
            const vec3 v_local = glm::transpose(tbn) * v;
            const float alpha = g.roughness * g.roughness;
            const uint32_t h = pcg_hash(uint32_t(x) ^ pcg_hash(uint32_t(y) ^ seed_hash));
            // trace_and_shade_w from the exact point, else trace_and_shade from generate_ray's
            // view-space origin
            const vec3 origin_w =
                st.exact ? st.origin_w : vec3(f.inv_view * vec4(p_view + n * (su.origin_bias * -p_view.z), 1.0f));
            vec4 acc = accum_[i];
            // The round's rays, 8 at a time: generated, traced, shaded and added in ray order (the
            // GLSL loop's order, so the same sums).
            for (int c0 = first; c0 < first + count; c0 += 8) {
                vec3 dirs[8] = {};
                float weights[8] = {};
                bool active[8] = {};
                const int lanes = std::min(first + count - c0, 8);
                for (int k = 0; k < lanes; ++k) {
                    const int r = c0 + k;
                    if (mirror && r > 0) break;
                    if (r >= su.rays_per_pixel) break;  // (rays_for_roughness without adaptive rays)
                    // ray_random: PCG noise and a Hammersley point (as the converged reference uploads)
                    vec2 u(unit_float(pcg_hash(h + 2u * uint32_t(r))), unit_float(pcg_hash(h + 2u * uint32_t(r) + 1u)));
                    if (su.hammersley != 0) {
                        const vec2 hm = hammersley(uint32_t(r), uint32_t(su.rays_per_pixel));
                        u = vec2(fract(u.x + hm.x), fract(u.y + hm.y));
                    }
                    const BrdfSample bs = sample_reflection(v_local, alpha, su.sampling, u);
                    const vec3 dir = glm::normalize(tbn * bs.l);
                    weights[k] = bs.weight;
                    active[k] = bs.weight > 0.0f;
                    dirs[k] = glm::normalize(sh.inv_view3_ * dir);
                }
                Hit hits[8];
                sh.trace_closest_n(origin_w, dirs, active, lanes, su.max_distance, hits);
                for (int k = 0; k < lanes; ++k) {
                    if (!active[k]) continue;
                    const ShadedHit s = sh.shade_hit(hits[k], dirs[k], s_.viewer_is_ray);
                    acc += vec4(weights[k] * s.radiance, weights[k]);
                }
            }
            accum_[i] = acc;
        }
        rays_ += sh.rays;
    });
}

// reference.comp's last dispatch: the normalised reflection and the pixel's own direct light.
void CpuReference::finish() {
    const FrameUniforms& f = s_.frame;
    const SsrUniforms& su = s_.ssr;
    parallel_rows([&](int y) {
        Shader sh(s_);
        for (int x = 0; x < width_; ++x) {
            const size_t i = size_t(y) * size_t(width_) + size_t(x);
            const GSample g = decode(gbuffer_[i]);
            const PixelState& st = state_[i];
            const vec3 pos = st.pos;
            const vec3 v = glm::normalize(-pos);
            const vec4 acc = accum_[i];
            vec3 reflection(0.0f), direct(0.0f);
            if (g.covered && g.reflectivity > 0.0f && g.roughness <= su.roughness_cutoff)
                reflection = acc.w > 0.0f ? vec3(acc) / acc.w
                                          : sh.environment_radiance(glm::normalize(sh.inv_view3_ * glm::reflect(-v, g.normal)));
            if (g.covered) {
                vec3 point_w, normal_w;
                if (st.exact) {
                    point_w = st.point_w;
                    normal_w = st.normal_w;
                } else {
                    point_w = vec3(f.inv_view * vec4(pos + g.normal * (su.origin_bias * -pos.z), 1.0f));
                    normal_w = glm::normalize(sh.inv_view3_ * g.normal);
                }
                // lib/gbuffer_emission.glsl: the G-buffer's emission, or the factor by object id.
                const vec3 emission =
                    !emission_.empty() ? vec3(emission_[i])
                                       : (g.object_id >= 0
                                              ? vec3(s_.materials[size_t(s_.objects[size_t(g.object_id)].material.x)].emissive)
                                              : vec3(0.0f));
                // lib/gbuffer_specular.glsl: the G-buffer's F0, or the factors' by object id.
                const vec3 dielectric =
                    !dielectric_f0_.empty() ? vec3(dielectric_f0_[i])
                                            : (g.object_id >= 0
                                                   ? vec3(s_.materials[size_t(s_.objects[size_t(g.object_id)].material.x)].dielectric_f0)
                                                   : vec3(0.04f));
                direct = sh.shade_surface(g, emission, dielectric, pos, glm::normalize(-pos), point_w, normal_w);
            }
            reflection_[i] = vec4(reflection, 1.0f);
            direct_[i] = vec4(direct, 1.0f);
        }
        rays_ += sh.rays;
    });
}

}  // namespace ssr
