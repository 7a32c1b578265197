// Sampling glTF animation channels and posing a scene's node tree (animation.h).

#include "scene/animation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/gtc/matrix_transform.hpp>

#include "core/errors.h"
#include "scene/scene.h"
#include "scene/scene_limits.h"

namespace ssr {

namespace {

std::string num(double v) { return number_text(v); }

// Spherical linear interpolation of unit quaternions a -> b at u in [0, 1], along the shorter
// arc (q and -q are the same rotation), as glTF's Appendix C describes it. Computed in double:
// the plain linear blend is needed only where the angle is too small for sin(theta0) to divide.
void slerp(const float* a, const float* b, double u, double* out) {
    double qb[4], d = 0.0;
    for (int i = 0; i < 4; ++i) d += double(a[i]) * double(b[i]);
    const double sign = d < 0.0 ? -1.0 : 1.0;
    for (int i = 0; i < 4; ++i) qb[i] = sign * double(b[i]);
    d = std::min(std::abs(d), 1.0);
    double wa = 1.0 - u, wb = u;
    if (d < 1.0 - 1e-12) {
        const double theta0 = std::acos(d), s = std::sin(theta0);
        wa = std::sin((1.0 - u) * theta0) / s;
        wb = std::sin(u * theta0) / s;
    }
    double len = 0.0;
    for (int i = 0; i < 4; ++i) {
        out[i] = wa * double(a[i]) + wb * qb[i];
        len += out[i] * out[i];
    }
    len = std::sqrt(len);
    if (len > 0.0)
        for (int i = 0; i < 4; ++i) out[i] /= len;
}

}  // namespace

glm::mat4 trs_matrix(const glm::vec3& translation, const glm::quat& rotation, const glm::vec3& scale) {
    return glm::translate(glm::mat4(1.0f), translation) * glm::mat4_cast(rotation) * glm::scale(glm::mat4(1.0f), scale);
}

glm::mat4 NodeTransform::local() const { return has_matrix ? matrix : trs_matrix(translation, glm::quat(rotation), scale); }

const char* interpolation_name(AnimationSampler::Interpolation i) {
    switch (i) {
        case AnimationSampler::Interpolation::Step: return "STEP";
        case AnimationSampler::Interpolation::CubicSpline: return "CUBICSPLINE";
        default: return "LINEAR";
    }
}

const char* path_name(AnimationChannel::Path p) {
    switch (p) {
        case AnimationChannel::Path::Rotation: return "rotation";
        case AnimationChannel::Path::Scale: return "scale";
        default: return "translation";
    }
}

std::string check_sampler(AnimationSampler& s) {
    const size_t n = s.times.size();
    if (s.components != 3 && s.components != 4) return "values must have 3 or 4 components";
    if (n == 0) return "has no keyframes";
    for (size_t i = 0; i < n; ++i)
        if (!std::isfinite(s.times[i])) return "keyframe time " + std::to_string(i) + " is not finite";
    if (s.times[0] < 0.0f) return "its first keyframe time is " + num(s.times[0]) + " s; glTF times start at 0 or later";
    for (size_t i = 1; i < n; ++i)
        if (!(s.times[i] > s.times[i - 1]))
            return "keyframe times must increase strictly, but time " + std::to_string(i) + " (" + num(s.times[i]) +
                   " s) follows " + num(s.times[i - 1]) + " s";
    const bool cubic = s.interpolation == AnimationSampler::Interpolation::CubicSpline;
    if (cubic && n < 2) return "CUBICSPLINE needs at least 2 keyframes, it has 1";
    const size_t per = cubic ? 3 : 1, c = size_t(s.components);
    if (s.values.size() != n * per * c)
        return "has " + std::to_string(s.values.size() / c) + " output values for " + std::to_string(n) + " keyframes; " +
               interpolation_name(s.interpolation) + " needs " +
               (cubic ? "3 per keyframe (in-tangent, value, out-tangent): " : "1 per keyframe: ") + std::to_string(n * per);
    for (size_t i = 0; i < s.values.size(); ++i)
        if (!std::isfinite(s.values[i]))
            return "output value " + std::to_string(i / c) + " is not finite";
    if (s.components == 4)  // the keyframes' quaternions (not the tangents) are unit rotations
        for (size_t k = 0; k < n; ++k) {
            float* q = s.values.data() + (k * per + (cubic ? 1 : 0)) * 4;
            double len = 0.0;
            for (int i = 0; i < 4; ++i) len += double(q[i]) * double(q[i]);
            len = std::sqrt(len);
            if (!(len > 1e-6)) return "rotation keyframe " + std::to_string(k) + " is a (near) zero quaternion";
            for (int i = 0; i < 4; ++i) q[i] = float(double(q[i]) / len);
        }
    return "";
}

void sample(const AnimationSampler& s, double t, double* out) {
    const int c = s.components;
    const size_t n = s.times.size();
    const bool cubic = s.interpolation == AnimationSampler::Interpolation::CubicSpline;
    const size_t per = cubic ? 3 : 1;
    // Keyframe k's in-tangent (0), value (1) or out-tangent (2); without tangents, its value.
    auto key = [&](size_t k, int which) { return s.values.data() + (k * per + (cubic ? size_t(which) : 0)) * size_t(c); };
    auto copy = [&](const float* v) {
        for (int i = 0; i < c; ++i) out[i] = double(v[i]);
    };
    if (!(t > double(s.times[0]))) return copy(key(0, 1));
    if (t >= double(s.times[n - 1])) return copy(key(n - 1, 1));
    // k: the last keyframe at or before t (t lies strictly inside the keyframes here).
    const size_t k = size_t(std::upper_bound(s.times.begin(), s.times.end(), t,
                                             [](double x, float y) { return x < double(y); }) -
                            s.times.begin()) - 1;
    const double t0 = s.times[k], td = double(s.times[k + 1]) - t0, u = (t - t0) / td;
    switch (s.interpolation) {
        case AnimationSampler::Interpolation::Step:
            return copy(key(k, 1));
        case AnimationSampler::Interpolation::Linear:
            if (c == 4) return slerp(key(k, 1), key(k + 1, 1), u, out);
            for (int i = 0; i < c; ++i) out[i] = (1.0 - u) * double(key(k, 1)[i]) + u * double(key(k + 1, 1)[i]);
            return;
        case AnimationSampler::Interpolation::CubicSpline: {
            // The cubic Hermite spline between values v0 and v1 with out-tangent b0 and in-tangent
            // a1, tangents scaled by the interval td (glTF 2.0 Appendix C).
            const double u2 = u * u, u3 = u2 * u;
            const double h00 = 2.0 * u3 - 3.0 * u2 + 1.0, h10 = u3 - 2.0 * u2 + u, h01 = -2.0 * u3 + 3.0 * u2,
                         h11 = u3 - u2;
            const float *v0 = key(k, 1), *b0 = key(k, 2), *v1 = key(k + 1, 1), *a1 = key(k + 1, 0);
            double len = 0.0;
            for (int i = 0; i < c; ++i) {
                out[i] = h00 * v0[i] + td * h10 * b0[i] + h01 * v1[i] + td * h11 * a1[i];
                len += out[i] * out[i];
            }
            len = std::sqrt(len);
            if (c == 4 && len > 0.0)
                for (int i = 0; i < 4; ++i) out[i] /= len;
            return;
        }
    }
}

std::vector<glm::mat4> node_world_transforms(const Scene& scene) {
    std::vector<glm::mat4> world(scene.nodes.size());
    for (size_t i = 0; i < scene.nodes.size(); ++i) {  // parents come before their children
        const SceneNode& n = scene.nodes[i];
        world[i] = (n.parent >= 0 ? world[size_t(n.parent)] : n.root_transform) * n.current.local();
    }
    return world;
}

ScenePose pose_animations(Scene& scene, const std::vector<std::pair<int, double>>& played) {
    const size_t count = scene.nodes.size();
    std::vector<char> targeted(count, 0), moved(count, 0);
    for (const auto& [a, t] : played) {
        if (a < 0 || a >= int(scene.animations.size()))
            throw std::out_of_range("animation index " + std::to_string(a) + " is out of range (the scene has " +
                                    std::to_string(scene.animations.size()) + " animations)");
        if (!std::isfinite(t)) throw std::invalid_argument("animation time must be finite");
        for (const AnimationChannel& ch : scene.animations[size_t(a)].channels) targeted[size_t(ch.node)] = 1;
    }
    // Channels replace their node's rest values; several animations on one node apply in order.
    for (size_t i = 0; i < count; ++i)
        if (targeted[i]) scene.nodes[i].current = scene.nodes[i].rest;
    for (const auto& [a, t] : played) {
        const Animation& anim = scene.animations[size_t(a)];
        for (const AnimationChannel& ch : anim.channels) {
            double v[4];
            sample(ch.sampler, t, v);
            NodeTransform& local = scene.nodes[size_t(ch.node)].current;
            switch (ch.path) {
                case AnimationChannel::Path::Translation: local.translation = glm::vec3(v[0], v[1], v[2]); break;
                case AnimationChannel::Path::Scale: local.scale = glm::vec3(v[0], v[1], v[2]); break;
                case AnimationChannel::Path::Rotation:
                    if (!(std::abs(v[0]) + std::abs(v[1]) + std::abs(v[2]) + std::abs(v[3]) > 0.0))
                        throw SceneError(anim.source + ": animation '" + anim.name + "' at t = " + num(t) + " s: node '" +
                                         scene.nodes[size_t(ch.node)].name +
                                         "': its cubic spline rotation passes through a zero quaternion");
                    local.rotation = glm::dquat(v[3], v[0], v[1], v[2]);
                    break;
            }
        }
    }
    ScenePose pose;
    const std::vector<glm::mat4> world = node_world_transforms(scene);
    for (size_t i = 0; i < count; ++i) {
        const SceneNode& n = scene.nodes[i];
        moved[i] = targeted[i] || (n.parent >= 0 && moved[size_t(n.parent)]);
        if (!moved[i]) continue;
        auto fail = [&](const std::string& what) {
            std::string names, source;
            for (const auto& [a, t] : played) {
                const Animation& anim = scene.animations[size_t(a)];
                names += (names.empty() ? "'" : ", '") + anim.name + "' at t = " + num(t) + " s";
                source = anim.source;
            }
            throw SceneError(source + ": animation " + names + ": node " + std::to_string(n.file_index) +
                             (n.name.empty() ? "" : " ('" + n.name + "')") + ": " + what);
        };
        const glm::mat4& w = world[i];
        for (int o : n.objects) {
            if (const std::string p = transform_problem(w); !p.empty()) fail("its world transform " + p);
            Bounds b;
            for (const auto& q : scene.meshes[size_t(scene.objects[size_t(o)].mesh)].positions) b.extend(q);
            if (const std::string p = world_bounds_problem(w, b.min, b.max); !p.empty()) fail(p);
            pose.objects.emplace_back(o, w);
        }
        if (n.light >= 0 && n.light < int(scene.lights.size())) {
            const glm::vec3 position(w[3]), back(w[2]);
            if (const std::string p = world_point_problem(position); !p.empty()) fail("its light " + p);
            const Light& l = scene.lights[size_t(n.light)];
            const float len = glm::length(back);
            const bool usable = std::isfinite(len) && len > 1e-20f && std::isfinite(1.0f / len);
            if (!usable && l.type != Light::Type::Point) fail("its light has no direction (the node's transform is degenerate)");
            pose.lights.push_back({n.light, position, usable ? -back / len : l.direction});
        }
    }
    return pose;
}

}  // namespace ssr
