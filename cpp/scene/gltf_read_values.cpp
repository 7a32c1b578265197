// The reader's checked numbers: finite, in range, and (for points and transforms) inside what
// the renderer can draw (scene_limits.h).

#include <glm/gtc/type_ptr.hpp>

#include "scene/gltf_reader.h"
#include "scene/scene_limits.h"

namespace ssr::gltf_detail {

bool in_range(double v, double lo, double hi) {
    return std::isfinite(v) && std::isfinite(float(v)) && v >= lo && v <= hi;
}

std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

void check_finite_list(const GltfReader& r, const std::vector<double>& v, const std::string& what) {
    for (double x : v)
        if (!in_range(x, -3.0e38, 3.0e38)) r.fail(what + " holds " + num(x) + ", not a finite float");
}

bool finite_matrix(const glm::mat4& m) {
    for (int i = 0; i < 16; ++i)
        if (!std::isfinite(glm::value_ptr(m)[i])) return false;
    return true;
}

glm::vec3 vec3_from(const std::vector<double>& v, glm::vec3 fallback) {
    return v.size() >= 3 ? glm::vec3(float(v[0]), float(v[1]), float(v[2])) : fallback;
}

glm::vec3 vec3_from_value(const tinygltf::Value& v, glm::vec3 fallback, const GltfReader& r, const std::string& what,
                          double lo, double hi) {
    if (v.Type() == tinygltf::NULL_TYPE) return fallback;
    if (!v.IsArray() || v.ArrayLen() != 3) r.fail(what + " must be an array of 3 numbers");
    glm::vec3 out;
    for (int i = 0; i < 3; ++i) {
        const auto& x = v.Get(i);
        if (!x.IsNumber() && !x.IsInt()) r.fail(what + " must be an array of 3 numbers");
        const double d = x.GetNumberAsDouble();
        if (!in_range(d, lo, hi)) r.fail(what + " holds " + num(d) + ", outside [" + num(lo) + ", " + num(hi) + "]");
        out[i] = float(d);
    }
    return out;
}

double number_from_value(const tinygltf::Value& v, const GltfReader& r, const std::string& what, double lo, double hi) {
    if (!v.IsNumber() && !v.IsInt()) r.fail(what + " must be a number");
    const double d = v.GetNumberAsDouble();
    if (!in_range(d, lo, hi)) r.fail(what + " is " + num(d) + ", outside [" + num(lo) + ", " + num(hi) + "]");
    return d;
}

std::string string_from_value(const tinygltf::Value& v, const GltfReader& r, const std::string& what) {
    if (!v.IsString()) r.fail(what + " must be a string");
    return v.Get<std::string>();
}

bool within_world(const glm::vec3& p) { return world_point_problem(p).empty(); }

bool invertible_transform(const glm::mat4& m) { return transform_problem(m).empty(); }

bool usable_direction(const glm::vec3& v) {
    const float len = glm::length(v);
    return std::isfinite(len) && len > 1e-20f && std::isfinite(1.0f / len);
}

}  // namespace ssr::gltf_detail
