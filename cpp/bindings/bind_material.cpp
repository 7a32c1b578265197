// ssrlab.Material: the glTF material's fields from Python; their domains are checked in the
// scene's C++ (validate_material), the Python-only parsing ('auto', glTF's alpha mode names) here.

#include "bindings/bindings.h"
#include "scene/scene.h"

namespace py = pybind11;

namespace ssr {

namespace {

// Material.reflectivity from Python: a number, or "auto" (kAutoReflectivity).
float reflectivity_from_python(const py::object& v) {
    if (py::isinstance<py::str>(v)) {
        if (v.cast<std::string>() != "auto")
            throw std::invalid_argument("Material.reflectivity must be a number in [0, 1] or 'auto', got '" +
                                        v.cast<std::string>() + "'");
        return kAutoReflectivity;
    }
    if (py::isinstance<py::bool_>(v) || !(py::isinstance<py::float_>(v) || py::isinstance<py::int_>(v) ||
                                          py::hasattr(v, "__float__")))
        throw py::type_error("Material.reflectivity must be a number in [0, 1] or 'auto'");
    const float r = v.cast<float>();
    if (!(r >= 0.0f && r <= 1.0f))
        throw std::invalid_argument("Material.reflectivity must be in [0, 1] or 'auto', got " + std::to_string(r));
    return r;
}

// Material.alpha_mode from Python: glTF's names.
Material::AlphaMode alpha_mode_from_python(const std::string& v) {
    if (v == "OPAQUE") return Material::AlphaMode::Opaque;
    if (v == "MASK") return Material::AlphaMode::Mask;
    if (v == "BLEND") return Material::AlphaMode::Blend;
    throw std::invalid_argument("Material.alpha_mode must be 'OPAQUE', 'MASK' or 'BLEND', got '" + v + "'");
}

const char* alpha_mode_name(Material::AlphaMode m) {
    return m == Material::AlphaMode::Mask ? "MASK" : (m == Material::AlphaMode::Blend ? "BLEND" : "OPAQUE");
}

// A property setter that checks the material as it would be with the new value (validate_material)
// before changing it: a refused value leaves the material as it was.
template <class T>
auto validated_setter(T Material::*field) {
    return [field](Material& x, const T& v) {
        Material t = x;
        t.*field = v;
        validate_material(t, nullptr);
        x.*field = v;
    };
}

}  // namespace

void bind_material(py::module_& m) {
    py::class_<Material>(m, "Material", R"doc(
A glTF 2.0 metallic-roughness material plus the thesis's reflectivity.

base_color   linear RGBA, each in [0, 1] (default (0.8, 0.8, 0.8, 1))
metallic     0..1
roughness    perceptual roughness 0..1, as in glTF; GGX alpha = roughness**2
reflectivity 0..1: r in the thesis's composite c = r*c_r + (1 - r)*c_d (seed 000, 2.4); or "auto":
             the surface reflects as its metallic-roughness parameters say (r = luminance of its
             GGX specular albedo F0 A + B at the pixel's view angle; glTF files without ssrlab's
             extras load so)
double_sided back faces show the other side (normals flipped), as glTF's doubleSided
ior, specular, specular_color
             KHR_materials_ior / KHR_materials_specular: a dielectric's F0 is
             min(((ior - 1) / (ior + 1))^2 x specular_color, 1) x specular (0.04 by default)
alpha_mode   glTF alphaMode: 'OPAQUE', 'MASK' (alpha = base_color[3] x texture alpha below
             alpha_cutoff is a hole in every pass) or 'BLEND' (tested as MASK at 0.5)
emissive     emitted linear RGB radiance (glTF emissiveFactor x emissive strength), each <= 1000;
             times the emissive_texture's sRGB-decoded texel where there is one
specular_texture, specular_color_texture
             KHR_materials_specular's textures: per texel, specular x the specular_texture's A
             and specular_color x the specular_color_texture's sRGB-decoded RGB in the F0 above
*_texture    image index in the scene (-1: none); see Scene.add_image
)doc")
        .def(py::init([](py::object base_color, float metallic, float roughness, py::object reflectivity, bool double_sided,
                         const std::string& name, int base_color_texture, int metallic_roughness_texture,
                         int normal_texture, float normal_scale, const std::string& alpha_mode, float alpha_cutoff,
                         int emissive_texture, int specular_texture, int specular_color_texture) {
                 Material mat;
                 if (!base_color.is_none()) {
                     auto seq = py::cast<std::vector<float>>(base_color);
                     if (seq.size() != 3 && seq.size() != 4)
                         throw std::invalid_argument("Material.base_color must have 3 or 4 components");
                     mat.base_color = glm::vec4(seq[0], seq[1], seq[2], seq.size() == 4 ? seq[3] : 1.0f);
                 }
                 mat.metallic = metallic;
                 mat.roughness = roughness;
                 mat.reflectivity = reflectivity_from_python(reflectivity);
                 mat.double_sided = double_sided;
                 mat.name = name;
                 mat.base_color_texture.image = base_color_texture;
                 mat.metallic_roughness_texture.image = metallic_roughness_texture;
                 mat.normal_texture.image = normal_texture;
                 mat.emissive_texture.image = emissive_texture;
                 mat.specular_texture.image = specular_texture;
                 mat.specular_color_texture.image = specular_color_texture;
                 mat.normal_scale = normal_scale;
                 mat.alpha_mode = alpha_mode_from_python(alpha_mode);
                 mat.alpha_cutoff = alpha_cutoff;
                 validate_material(mat, nullptr);
                 return mat;
             }),
             py::kw_only(), py::arg("base_color") = py::none(), py::arg("metallic") = 0.0f,
             py::arg("roughness") = 0.5f, py::arg("reflectivity") = 0.0f, py::arg("double_sided") = false,
             py::arg("name") = "", py::arg("base_color_texture") = -1, py::arg("metallic_roughness_texture") = -1,
             py::arg("normal_texture") = -1, py::arg("normal_scale") = 1.0f, py::arg("alpha_mode") = "OPAQUE",
             py::arg("alpha_cutoff") = 0.5f, py::arg("emissive_texture") = -1,
             py::arg("specular_texture") = -1, py::arg("specular_color_texture") = -1)
        .def_readwrite("name", &Material::name, "the material's name (glTF material name)")
        .def_readwrite("base_color", &Material::base_color, "linear RGBA base colour, each >= 0")
        .def_readwrite("metallic", &Material::metallic, "glTF metalness, 0..1")
        .def_readwrite("roughness", &Material::roughness, "perceptual roughness 0..1 (GGX alpha = roughness**2)")
        .def_property(
            "reflectivity",
            [](const Material& x) -> py::object {
                if (x.auto_reflectivity()) return py::str("auto");
                return py::float_(x.reflectivity);
            },
            [](Material& x, py::object v) {
                const float r = reflectivity_from_python(v);
                if (!(r == kAutoReflectivity || (r >= 0.0f && r <= 1.0f)))
                    throw std::invalid_argument("Material.reflectivity must be in [0, 1] or 'auto', got " +
                                                std::to_string(r));
                x.reflectivity = r;
            },
            "r in [0, 1] of the thesis's composite, or 'auto' (reflects as the metallic-roughness parameters say)")
        .def_readwrite("double_sided", &Material::double_sided, "back faces show the other side (normals flipped)")
        .def_property(
            "alpha_mode", [](const Material& x) { return std::string(alpha_mode_name(x.alpha_mode)); },
            [](Material& x, const std::string& v) { x.alpha_mode = alpha_mode_from_python(v); },
            "glTF alphaMode: 'OPAQUE', 'MASK' (texels with alpha below alpha_cutoff are holes in every "
            "visibility pass) or 'BLEND' (tested as MASK at 0.5)")
        .def_property(
            "ior", [](const Material& x) { return x.ior; },
            validated_setter(&Material::ior),
            "index of refraction (KHR_materials_ior; 1.5 gives glTF's dielectric F0 0.04)")
        .def_property(
            "specular", [](const Material& x) { return x.specular; },
            validated_setter(&Material::specular),
            "KHR_materials_specular specularFactor in [0, 1]: scales a dielectric's F0")
        .def_property(
            "specular_color", [](const Material& x) { return x.specular_color; },
            validated_setter(&Material::specular_color),
            "KHR_materials_specular specularColorFactor (linear RGB, >= 0): tints a dielectric's F0")
        .def_property_readonly(
            "dielectric_f0", [](const Material& x) { return x.dielectric_f0(); },
            "a dielectric's specular reflectance at normal incidence from ior, specular and specular_color "
            "(the factors; specular_texture and specular_color_texture scale them per texel)")
        .def_property(
            "alpha_cutoff", [](const Material& x) { return x.alpha_cutoff; },
            [](Material& x, float c) {
                check_alpha_cutoff(c);
                x.alpha_cutoff = c;
            },
            "glTF alphaCutoff of a MASK material: alpha = base_color[3] x base colour texture alpha")
        .def_property(
            "emissive", [](const Material& x) { return x.emissive; },
            [](Material& x, const glm::vec3& e) {
                check_emissive(e);
                x.emissive = e;
            },
            "emitted radiance, linear RGB: glTF emissiveFactor x KHR_materials_emissive_strength (added to the lit "
            "colour; times the emissive_texture's texel where there is one)")
        .def_readwrite("normal_scale", &Material::normal_scale, "glTF normal-texture scale of the tangent-space xy")
        .def_property(
            "base_color_texture", [](const Material& x) { return x.base_color_texture.image; },
            [](Material& x, int i) { x.base_color_texture.image = i; }, "image index of the base colour texture (-1: none)")
        .def_property(
            "metallic_roughness_texture", [](const Material& x) { return x.metallic_roughness_texture.image; },
            [](Material& x, int i) { x.metallic_roughness_texture.image = i; },
            "image index of the glTF metallic (B) roughness (G) texture (-1: none)")
        .def_property(
            "normal_texture", [](const Material& x) { return x.normal_texture.image; },
            [](Material& x, int i) { x.normal_texture.image = i; }, "image index of the tangent-space normal texture (-1: none)")
        .def_property(
            "emissive_texture", [](const Material& x) { return x.emissive_texture.image; },
            [](Material& x, int i) { x.emissive_texture.image = i; },
            "image index of the sRGB emissive texture (-1: none): the emitted radiance is emissive x its texel "
            "(glTF emissiveTexture)")
        .def_property(
            "specular_texture", [](const Material& x) { return x.specular_texture.image; },
            [](Material& x, int i) { x.specular_texture.image = i; },
            "image index of the KHR_materials_specular specularTexture (-1: none): its (linear) A channel "
            "multiplies specular per texel")
        .def_property(
            "specular_color_texture", [](const Material& x) { return x.specular_color_texture.image; },
            [](Material& x, int i) { x.specular_color_texture.image = i; },
            "image index of the KHR_materials_specular specularColorTexture (-1: none): its sRGB-decoded RGB "
            "multiplies specular_color per texel")
        .def("__repr__", [](const Material& x) {
            return "Material(name='" + x.name + "', base_color=(" + std::to_string(x.base_color.r) + ", " +
                   std::to_string(x.base_color.g) + ", " + std::to_string(x.base_color.b) +
                   "), metallic=" + std::to_string(x.metallic) + ", roughness=" + std::to_string(x.roughness) +
                   ", reflectivity=" + (x.auto_reflectivity() ? std::string("'auto'") : std::to_string(x.reflectivity)) +
                   ")";
        });
}

}  // namespace ssr
