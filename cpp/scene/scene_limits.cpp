#include "scene/scene_limits.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "scene/scene.h"

namespace ssr {

std::string number_text(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

namespace {
std::string num(double v) { return number_text(v); }
bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
}  // namespace

std::string affine_problem(const glm::mat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return "contains NaN or Inf";
    // glm is column-major: the bottom row is m[0..3][3].
    const double bottom[4] = {m[0][3], m[1][3], m[2][3], m[3][3] - 1.0};
    for (double b : bottom)
        if (std::abs(b) > kAffineTolerance)
            return "is not affine: its bottom row is (" + num(m[0][3]) + ", " + num(m[1][3]) + ", " + num(m[2][3]) +
                   ", " + num(m[3][3]) + "), not (0, 0, 0, 1)";
    return "";
}

std::string transform_problem(const glm::mat4& m) {
    if (std::string p = affine_problem(m); !p.empty()) return p;
    const glm::dmat3 a{glm::mat3(m)};
    const double l0 = glm::length(a[0]), l1 = glm::length(a[1]), l2 = glm::length(a[2]);
    const double scale = l0 * l1 * l2;
    const double det = glm::determinant(a);
    if (!std::isfinite(scale) || !(scale > 0.0) || !(std::abs(det) > 1e-6 * scale))
        return "is singular (a zero scale, or axes that are parallel)";
    if (std::max({l0, l1, l2}) > kMaxScaleRatio * std::min({l0, l1, l2}))
        return "scales its axes more than " + num(kMaxScaleRatio) + " apart (" + num(std::min({l0, l1, l2})) + " to " +
               num(std::max({l0, l1, l2})) + ")";
    // Normals go through the inverse transpose in float: it must be finite too.
    const glm::mat3 n = glm::transpose(glm::inverse(glm::mat3(m)));
    for (int c = 0; c < 3; ++c)
        if (!finite3(n[c])) return "has an inverse that overflows float (scale " + num(std::cbrt(std::abs(det))) + ")";
    return "";
}

std::string world_bounds_problem(const glm::mat4& m, const glm::vec3& lo, const glm::vec3& hi) {
    for (int k = 0; k < 8; ++k) {
        const glm::dvec3 corner((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
        const glm::dvec3 w(glm::dmat4(m) * glm::dvec4(corner, 1.0));
        if (!(std::abs(w.x) <= kMaxWorldCoordinate && std::abs(w.y) <= kMaxWorldCoordinate &&
              std::abs(w.z) <= kMaxWorldCoordinate))
            return "reaches (" + num(w.x) + ", " + num(w.y) + ", " + num(w.z) + ") in world space, beyond +-" +
                   num(kMaxWorldCoordinate);
    }
    return "";
}

std::string radiance_problem(const glm::vec3& rgb, float intensity) {
    if (!finite3(rgb) || !std::isfinite(intensity)) return "holds NaN or Inf";
    if (rgb.x < 0.0f || rgb.y < 0.0f || rgb.z < 0.0f || intensity < 0.0f) return "is negative";
    const double peak = double(std::max({rgb.x, rgb.y, rgb.z})) * double(intensity);
    if (peak > kMaxRadiance)
        return "colour x intensity " + num(peak) + " is more than " + num(kMaxRadiance) +
               " (the half-float lighting buffers would overflow)";
    return "";
}

std::string light_problem(const Light& l) {
    if (!finite3(l.color) || !std::isfinite(l.intensity)) return "colour or intensity holds NaN or Inf";
    if (l.color.x < 0.0f || l.color.y < 0.0f || l.color.z < 0.0f) return "colour must be >= 0";
    if (l.intensity < 0.0f) return "intensity must be >= 0";
    const double peak = double(std::max({l.color.x, l.color.y, l.color.z})) * double(l.intensity);
    if (peak > kMaxLightPower)
        return "colour x intensity " + num(peak) + " is more than " + num(kMaxLightPower) +
               " (the half-float lighting buffers would overflow)";
    if (!std::isfinite(l.range) || l.range < 0.0f) return "range must be finite and >= 0 (0: no end)";
    if (l.type == Light::Type::Spot &&
        !(l.inner_cone >= 0.0f && l.outer_cone > 0.0f && l.inner_cone < l.outer_cone && l.outer_cone <= 1.5707964f))
        return "spot cone angles must satisfy 0 <= inner_cone < outer_cone <= pi/2";
    if (l.type != Light::Type::Point) {
        const float len = glm::length(l.direction);
        if (!finite3(l.direction) || !(len > 1e-20f) || !std::isfinite(1.0f / len))
            return "direction must be a finite, non-zero vector";
    }
    if (l.type != Light::Type::Directional) {
        if (!finite3(l.position)) return "position must be finite";
        const std::string p = world_point_problem(l.position);
        if (!p.empty()) return "position " + p;
    }
    return "";
}

std::string world_point_problem(const glm::vec3& p) {
    if (!finite3(p)) return "holds NaN or Inf";
    if (!(std::abs(p.x) <= kMaxWorldCoordinate && std::abs(p.y) <= kMaxWorldCoordinate &&
          std::abs(p.z) <= kMaxWorldCoordinate))
        return "(" + num(p.x) + ", " + num(p.y) + ", " + num(p.z) + ") is beyond +-" + num(kMaxWorldCoordinate) +
               " in world space";
    return "";
}

}  // namespace ssr
