// ssrlab.Environment: what the background and rays that leave the screen see.

#include "bindings/bindings.h"
#include "scene/scene.h"

namespace py = pybind11;

namespace ssr {

void bind_environment(py::module_& m) {
    py::class_<Environment>(m, "Environment", R"doc(
What a pixel without geometry, or a reflection ray that leaves the screen, sees: a constant
colour, a procedural gradient sky, or an equirectangular map (EXR/HDR/PNG via OpenImageIO).)doc")
        .def_static(
            "constant",
            [](glm::vec3 color, float intensity) {
                Environment e;
                e.type = Environment::Type::Constant;
                e.color = color;
                e.intensity = intensity;
                return e;
            },
            py::arg("color") = glm::vec3(0.0f), py::arg("intensity") = 1.0f)
        .def_static(
            "sky",
            [](glm::vec3 zenith, glm::vec3 horizon, glm::vec3 ground, float intensity) {
                Environment e;
                e.type = Environment::Type::Sky;
                e.sky_zenith = zenith;
                e.sky_horizon = horizon;
                e.ground = ground;
                e.intensity = intensity;
                return e;
            },
            py::arg("zenith") = glm::vec3(0.25f, 0.45f, 0.85f), py::arg("horizon") = glm::vec3(0.8f, 0.85f, 0.9f),
            py::arg("ground") = glm::vec3(0.3f, 0.28f, 0.25f), py::arg("intensity") = 1.0f)
        .def_static(
            "map",
            [](const std::string& path, float intensity) { return environment_map(path, intensity); },
            py::arg("path"), py::arg("intensity") = 1.0f)
        .def_property_readonly("type",
                               [](const Environment& e) {
                                   return e.type == Environment::Type::Constant ? "constant"
                                          : e.type == Environment::Type::Sky    ? "sky"
                                                                                : "map";
                               },
                               "'constant', 'sky' or 'map'")
        .def_readwrite("color", &Environment::color, "linear RGB of a constant environment")
        .def_readwrite("zenith", &Environment::sky_zenith, "sky colour straight up (linear RGB)")
        .def_readwrite("horizon", &Environment::sky_horizon, "sky colour at the horizon (linear RGB)")
        .def_readwrite("ground", &Environment::ground, "colour below the horizon (linear RGB)")
        .def_readonly("map_path", &Environment::map_path, "file of an equirectangular map environment ('' otherwise)")
        .def_readwrite("intensity", &Environment::intensity, "scale of the environment's radiance")
        .def("__repr__", [](const Environment& e) {
            return std::string("Environment(") +
                   (e.type == Environment::Type::Constant ? "constant" : e.type == Environment::Type::Sky ? "sky" : "map") +
                   ", intensity=" + std::to_string(e.intensity) + ")";
        });
}

}  // namespace ssr
