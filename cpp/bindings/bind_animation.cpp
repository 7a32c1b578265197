// Animation from Python: the glTF animations a scene holds, the pose they give at a time, the
// keyframes of ssrlab.Keyframes (sampled by the same code as glTF's), and setting a light.
#include <cmath>
#include <optional>

#include "bindings/bindings.h"
#include "core/errors.h"
#include "scene/animation.h"
#include "scene/scene.h"
#include "scene/scene_limits.h"

namespace py = pybind11;

namespace ssr {

namespace {

// ssrlab.Keyframes' channels, checked once when made.
struct Keyframes {
    std::optional<AnimationSampler> translation, rotation, scale;
};

AnimationSampler::Interpolation interpolation_from(const std::string& name) {
    if (name == "linear") return AnimationSampler::Interpolation::Linear;
    if (name == "step") return AnimationSampler::Interpolation::Step;
    if (name == "cubicspline") return AnimationSampler::Interpolation::CubicSpline;
    throw std::invalid_argument("Keyframes.interpolation must be 'linear', 'step' or 'cubicspline', got '" + name + "'");
}

// One channel's values: (k, c), or (k, 3, c) for cubicspline (in-tangent, value, out-tangent).
std::optional<AnimationSampler> channel_from(const std::vector<float>& times, const py::object& values,
                                             AnimationSampler::Interpolation interpolation, int components,
                                             const char* name) {
    if (values.is_none()) return std::nullopt;
    const std::string what = std::string("Keyframes.") + name;
    auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(values);
    const bool cubic = interpolation == AnimationSampler::Interpolation::CubicSpline;
    const std::string shape = cubic ? "(k, 3, " + std::to_string(components) + ") (in-tangent, value, out-tangent per keyframe)"
                                    : "(k, " + std::to_string(components) + ")";
    if (!a || a.ndim() != (cubic ? 3 : 2) || a.shape(a.ndim() - 1) != components || (cubic && a.shape(1) != 3))
        throw std::invalid_argument(what + " must be an array of shape " + shape);
    if (size_t(a.shape(0)) != times.size())
        throw std::invalid_argument(what + " has " + std::to_string(a.shape(0)) + " keyframes, times has " +
                                    std::to_string(times.size()));
    AnimationSampler s;
    s.interpolation = interpolation;
    s.components = components;
    s.times = times;
    s.values.assign(a.data(), a.data() + a.size());
    if (const std::string p = check_sampler(s); !p.empty()) throw std::invalid_argument(what + ": " + p);
    return s;
}

py::tuple sampled(const std::optional<AnimationSampler>& s, double t) {
    if (!s) return py::tuple();
    double v[4];
    sample(*s, t, v);
    py::tuple out(size_t(s->components));
    for (int i = 0; i < s->components; ++i) out[size_t(i)] = py::float_(v[i]);
    return out;
}

}  // namespace

void bind_animation(py::module_& m) {
    py::class_<Animation>(m, "Animation", R"doc(
A glTF animation of a loaded scene (Scene.animations): channels that move nodes' translation,
rotation and scale, sampled as the glTF 2.0 specification's Appendix C says (STEP, LINEAR with
slerp for rotations, CUBICSPLINE). Scene.play(name or index) plays it.)doc")
        .def_readonly("name", &Animation::name, "the animation's name in the file ('animationN' when it has none)")
        .def_readonly("source", &Animation::source, "the file it was loaded from")
        .def_readonly("duration", &Animation::duration, "seconds: the last keyframe time over its channels")
        .def_property_readonly(
            "channels",
            [](const Animation& a) {
                py::list out;
                for (const AnimationChannel& c : a.channels)
                    out.append(py::make_tuple(c.node, path_name(c.path), interpolation_name(c.sampler.interpolation),
                                              c.sampler.times.size()));
                return out;
            },
            "(node, path, interpolation, keyframes) of each channel; node indexes the scene's animated nodes")
        .def("__repr__", [](const Animation& a) {
            char seconds[32];
            std::snprintf(seconds, sizeof seconds, "%g", double(a.duration));
            return "Animation('" + a.name + "', " + std::to_string(a.channels.size()) + " channels, " + seconds + " s)";
        });

    auto scene = py::reinterpret_borrow<py::class_<Scene>>(m.attr("Scene"));
    scene
        .def_property_readonly("animations", [](const Scene& s) { return s.animations; },
                               "the glTF animations of the files loaded into this scene (copies), in load order")
        .def_property_readonly(
            "node_names", [](const Scene& s) {
                std::vector<std::string> out;
                for (const SceneNode& n : s.nodes) out.push_back(n.name);
                return out;
            },
            "names of the nodes of animated glTF files (Animation.channels index them)")
        .def(
            "_pose",
            [](Scene& s, const std::vector<std::pair<int, double>>& played) {
                const ScenePose pose = pose_animations(s, played);
                py::list objects, lights;
                for (const auto& [o, m] : pose.objects) objects.append(py::make_tuple(o, m));
                for (const auto& l : pose.lights) {
                    Light light = s.lights[size_t(l.light)];
                    light.position = l.position;
                    light.direction = l.direction;
                    lights.append(py::make_tuple(l.light, light));
                }
                return py::make_tuple(objects, lights);
            },
            py::arg("played"),
            "Poses the animated nodes for [(animation, seconds)]: sets the nodes' transforms and returns "
            "([(object, 4x4 world transform)], [(light, Light)]) for the objects and lights they move.")
        .def(
            "set_light",
            [](Scene& s, int index, const Light& l) {
                if (index < 0 || index >= int(s.lights.size()))
                    throw py::index_error("light index " + std::to_string(index) + " out of range (scene has " +
                                          std::to_string(s.lights.size()) + " lights)");
                if (const std::string p = light_problem(l); !p.empty())
                    throw std::invalid_argument("light " + std::to_string(index) + " ('" + l.name + "'): " + p);
                s.lights[size_t(index)] = l;
                s.touch_lights();  // the lights alone: no geometry, no history lost
            },
            py::arg("index"), py::arg("light"), "Replaces light `index` by a copy of `light` (Scene.lights gives copies).");

    py::class_<Keyframes>(m, "_Keyframes")
        .def(py::init([](const std::vector<float>& times, py::object translation, py::object rotation, py::object scale,
                         const std::string& interpolation) {
                 const auto i = interpolation_from(interpolation);
                 Keyframes k;
                 k.translation = channel_from(times, translation, i, 3, "translation");
                 k.rotation = channel_from(times, rotation, i, 4, "rotation");
                 k.scale = channel_from(times, scale, i, 3, "scale");
                 return k;
             }),
             py::arg("times"), py::arg("translation"), py::arg("rotation"), py::arg("scale"), py::arg("interpolation"))
        .def("sample",
             [](const Keyframes& k, double t) {
                 return py::make_tuple(sampled(k.translation, t), sampled(k.rotation, t), sampled(k.scale, t));
             },
             py::arg("t"), "(translation, rotation x y z w, scale) at t; an empty tuple for a channel not given")
        .def("matrix",
             [](const Keyframes& k, double t) {
                 double v[4];
                 glm::vec3 tr(0.0f), sc(1.0f);
                 glm::quat rot(1.0f, 0.0f, 0.0f, 0.0f);
                 if (k.translation) sample(*k.translation, t, v), tr = glm::vec3(v[0], v[1], v[2]);
                 if (k.rotation) sample(*k.rotation, t, v), rot = glm::quat(float(v[3]), float(v[0]), float(v[1]), float(v[2]));
                 if (k.scale) sample(*k.scale, t, v), sc = glm::vec3(v[0], v[1], v[2]);
                 return trs_matrix(tr, rot, sc);
             },
             py::arg("t"), "translate x rotate x scale at t (a channel not given: identity)");
}

}  // namespace ssr
