// ssrlab.Light: punctual lights, made by the scene's C++ (directional_light, point_light,
// spot_light), which checks their values.

#include "bindings/bindings.h"
#include "scene/scene.h"

namespace py = pybind11;

namespace ssr {

namespace {

const char* light_type_name(const Light& l) {
    return l.type == Light::Type::Directional ? "directional" : (l.type == Light::Type::Spot ? "spot" : "point");
}

}  // namespace

void bind_light(py::module_& m) {
    py::class_<Light>(m, "Light", R"doc(
A punctual light. Directional: `intensity` is the irradiance (W/m^2) on a surface facing the
light, `direction` the direction the light travels. Point: `intensity` is the radiant
intensity (W/sr) at `position`, falling off as 1/d^2. Spot: a point light shining down
`direction`, full inside `inner_cone`, nothing beyond `outer_cone` (radians), with
KHR_lights_punctual's smooth falloff between. Point and spot lights end at `range` with the
extension's window (0: no end). Every light with cast_shadow=True casts a shadow: a directional
light an orthographic shadow map over the scene, a spot light a perspective one over its cone, a
point light a cube map (six faces). glTF lights cast by default when directional or spot, not
when point; extras.cast_shadow overrides either.)doc")
        .def_static(
            "directional",
            [](glm::vec3 direction, glm::vec3 color, float intensity, bool cast_shadow, const std::string& name) {
                return directional_light(direction, color, intensity, cast_shadow, name);
            },
            py::arg("direction"), py::arg("color") = glm::vec3(1.0f), py::arg("intensity") = 3.0f,
            py::arg("cast_shadow") = true, py::arg("name") = "sun")
        .def_static(
            "point",
            [](glm::vec3 position, glm::vec3 color, float intensity, const std::string& name) {
                return point_light(position, color, intensity, name);
            },
            py::arg("position"), py::arg("color") = glm::vec3(1.0f), py::arg("intensity") = 10.0f,
            py::arg("name") = "point")
        .def_static(
            "spot",
            [](glm::vec3 position, glm::vec3 direction, float inner_cone, float outer_cone, glm::vec3 color,
               float intensity, float range, const std::string& name) {
                return spot_light(position, direction, inner_cone, outer_cone, color, intensity, range, name);
            },
            py::arg("position"), py::arg("direction"), py::arg("inner_cone") = 0.0f, py::arg("outer_cone") = 0.7853982f,
            py::arg("color") = glm::vec3(1.0f), py::arg("intensity") = 10.0f, py::arg("range") = 0.0f,
            py::arg("name") = "spot")
        .def_property_readonly("type", [](const Light& l) { return light_type_name(l); },
                               "'directional', 'point' or 'spot'")
        .def_readwrite("inner_cone", &Light::inner_cone, "spot: full intensity within this angle of direction (radians)")
        .def_readwrite("outer_cone", &Light::outer_cone, "spot: no light beyond this angle of direction (radians)")
        .def_readwrite("range", &Light::range, "point and spot: where the light ends (KHR_lights_punctual window); 0 = no end")
        .def_readwrite("name", &Light::name, "the light's name")
        .def_readwrite("color", &Light::color, "linear RGB colour, multiplied by intensity")
        .def_readwrite("intensity", &Light::intensity, "irradiance W/m^2 (directional) or radiant intensity W/sr (point)")
        .def_readwrite("direction", &Light::direction, "world direction the light travels (directional lights)")
        .def_readwrite("position", &Light::position, "world position (point lights)")
        .def_readwrite("cast_shadow", &Light::cast_shadow, "casts a shadow: a 2D shadow map (directional, spot) or a cube map (point)")
        .def("__repr__", [](const Light& l) {
            return std::string("Light(") + light_type_name(l) + ", '" +
                   l.name + "', intensity=" + std::to_string(l.intensity) + ")";
        });
}

}  // namespace ssr
