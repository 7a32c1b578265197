#include <cmath>
#include <cstring>
#include <filesystem>
#include <pybind11/functional.h>

#include "bindings/bindings.h"
#include "scene/scene_limits.h"
#include "core/errors.h"
#include "render/camera.h"
#include "scene/embree_scene.h"
#include "scene/gltf_io.h"
#include "scene/image_io.h"
#include "scene/primitives.h"
#include "scene/scene.h"

namespace py = pybind11;

namespace ssr {

namespace {

const char* light_type_name(const Light& l) {
    return l.type == Light::Type::Directional ? "directional" : (l.type == Light::Type::Spot ? "spot" : "point");
}

// The last line behind ssrlab.Scene.add_mesh's own checks: forcecast would turn bool,
// complex (dropping the imaginary part), strings and dates into numbers without a word.
void require_real(const py::handle& obj, const char* what) {
    if (!py::isinstance<py::array>(obj)) return;  // lists etc.: forcecast parses them or fails
    const char kind = py::reinterpret_borrow<py::array>(obj).dtype().kind();
    if (kind != 'i' && kind != 'u' && kind != 'f')
        throw py::type_error(std::string(what) + " must hold real numbers (integer or float), got dtype kind '" +
                             kind + "'");
}

template <typename T, int N>
std::vector<glm::vec<N, float>> rows_of(const py::handle& obj, const char* what, size_t expect = 0) {
    require_real(obj, what);
    auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(obj);
    if (!a || a.ndim() != 2 || a.shape(1) != N)
        throw std::invalid_argument(std::string(what) + " must be an array of shape (n, " + std::to_string(N) + ")");
    if (expect && size_t(a.shape(0)) != expect)
        throw std::invalid_argument(std::string(what) + " has " + std::to_string(a.shape(0)) + " rows, expected " +
                                    std::to_string(expect) + " (one per vertex)");
    std::vector<glm::vec<N, float>> out(size_t(a.shape(0)));
    auto r = a.template unchecked<2>();
    for (py::ssize_t i = 0; i < a.shape(0); ++i)
        for (int c = 0; c < N; ++c) out[size_t(i)][c] = r(i, c);
    return out;
}

std::vector<uint32_t> indices_of(const py::handle& obj) {
    require_real(obj, "indices");
    // Fractional or NaN indices would be truncated by the cast below: refuse them first.
    if (auto f = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj)) {
        const double* q = f.data();
        for (py::ssize_t i = 0; i < f.size(); ++i)
            if (!std::isfinite(q[i]) || q[i] != std::floor(q[i]))
                throw std::invalid_argument("indices must be whole numbers: " + std::to_string(q[i]) +
                                            " at position " + std::to_string(i));
    }
    auto a = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(obj);
    if (!a) throw std::invalid_argument("indices must be an integer array of shape (m, 3) or (3m,)");
    if (a.size() == 0) throw std::invalid_argument("indices is empty; pass None for a non-indexed triangle list");
    if (!(a.ndim() == 1 || (a.ndim() == 2 && a.shape(1) == 3)))
        throw std::invalid_argument("indices must have shape (m, 3) or (3m,)");
    std::vector<uint32_t> out(size_t(a.size()));
    const int64_t* p = a.data();
    for (size_t i = 0; i < out.size(); ++i) {
        if (p[i] < 0 || p[i] > int64_t(UINT32_MAX))
            throw std::invalid_argument("indices: value " + std::to_string(p[i]) + " at position " + std::to_string(i) +
                                        " is out of range");
        out[i] = uint32_t(p[i]);
    }
    return out;
}

void check_object(const Scene& s, int obj) {
    if (obj < 0 || obj >= int(s.objects.size()))
        throw py::index_error("object index " + std::to_string(obj) + " out of range (scene has " +
                              std::to_string(s.objects.size()) + " objects)");
}

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

void validate_material(const Material& m, const Scene* scene) {
    auto unit = [](float v, const char* name) {
        if (!(v >= 0.0f && v <= 1.0f))
            throw std::invalid_argument(std::string("Material.") + name + " must be in [0, 1], got " + std::to_string(v));
    };
    for (int i = 0; i < 4; ++i)
        // The G-buffer stores albedo as sRGB8 (depth_peel.cpp): a component above 1 would be
        // clamped there without a word, as glTF's baseColorFactor range [0, 1] also says.
        if (!(m.base_color[i] >= 0.0f && m.base_color[i] <= 1.0f))
            throw std::invalid_argument("Material.base_color components must be in [0, 1], got " +
                                        std::to_string(m.base_color[i]));
    unit(m.metallic, "metallic");
    unit(m.roughness, "roughness");
    if (!m.auto_reflectivity()) unit(m.reflectivity, "reflectivity");
    if (!(m.ior == 0.0f || (m.ior >= 1.0f && m.ior <= 1e6f)))
        throw std::invalid_argument("Material.ior must be 0 or in [1, 1e6] (KHR_materials_ior), got " + std::to_string(m.ior));
    unit(m.specular, "specular");
    for (int i = 0; i < 3; ++i)
        if (!(m.specular_color[i] >= 0.0f && m.specular_color[i] <= 1e6f))
            throw std::invalid_argument("Material.specular_color components must be in [0, 1e6], got " +
                                        std::to_string(m.specular_color[i]));
    if (!(m.alpha_cutoff >= 0.0f && std::isfinite(m.alpha_cutoff)))
        throw std::invalid_argument("Material.alpha_cutoff must be finite and >= 0, got " + std::to_string(m.alpha_cutoff));
    if (scene) {
        for (const TextureRef* t : {&m.base_color_texture, &m.metallic_roughness_texture, &m.normal_texture,
                                    &m.emissive_texture, &m.specular_texture, &m.specular_color_texture})
            if (t->image >= int(scene->images.size()))
                throw std::invalid_argument("Material texture refers to image " + std::to_string(t->image) +
                                            ", but the scene has " + std::to_string(scene->images.size()) + " images");
    }
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

int add_mesh_object(Scene& s, Mesh mesh, const Material& material, const glm::mat4& transform, const std::string& name) {
    validate_material(material, &s);
    const int mi = s.add_mesh(std::move(mesh));
    const int mat = s.add_material(material);
    return s.add_object(mi, mat, transform, name);
}

}  // namespace

void bind_scene(py::module_& m) {
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
                if (!(c >= 0.0f && std::isfinite(c)))
                    throw std::invalid_argument("Material.alpha_cutoff must be finite and >= 0, got " +
                                                std::to_string(c));
                x.alpha_cutoff = c;
            },
            "glTF alphaCutoff of a MASK material: alpha = base_color[3] x base colour texture alpha")
        .def_property(
            "emissive", [](const Material& x) { return x.emissive; },
            [](Material& x, const glm::vec3& e) {
                if (const std::string p = radiance_problem(e, 1.0f); !p.empty())
                    throw std::invalid_argument("Material.emissive " + p);
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
                if (glm::length(direction) < 1e-8f) throw std::invalid_argument("Light.direction must be non-zero");
                if (!(intensity >= 0.0f)) throw std::invalid_argument("Light.intensity must be >= 0");
                Light l;
                l.type = Light::Type::Directional;
                l.direction = glm::normalize(direction);
                l.color = color;
                l.intensity = intensity;
                l.cast_shadow = cast_shadow;
                l.name = name;
                return l;
            },
            py::arg("direction"), py::arg("color") = glm::vec3(1.0f), py::arg("intensity") = 3.0f,
            py::arg("cast_shadow") = true, py::arg("name") = "sun")
        .def_static(
            "point",
            [](glm::vec3 position, glm::vec3 color, float intensity, const std::string& name) {
                if (!(intensity >= 0.0f)) throw std::invalid_argument("Light.intensity must be >= 0");
                Light l;
                l.type = Light::Type::Point;
                l.position = position;
                l.color = color;
                l.intensity = intensity;
                l.name = name;
                return l;
            },
            py::arg("position"), py::arg("color") = glm::vec3(1.0f), py::arg("intensity") = 10.0f,
            py::arg("name") = "point")
        .def_static(
            "spot",
            [](glm::vec3 position, glm::vec3 direction, float inner_cone, float outer_cone, glm::vec3 color,
               float intensity, float range, const std::string& name) {
                Light l;
                l.type = Light::Type::Spot;
                l.position = position;
                l.direction = direction;
                l.inner_cone = inner_cone;
                l.outer_cone = outer_cone;
                l.color = color;
                l.intensity = intensity;
                l.range = range;
                l.name = name;
                if (const std::string p = light_problem(l); !p.empty()) throw std::invalid_argument("spot light: " + p);
                l.direction = glm::normalize(direction);
                return l;
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
            [](const std::string& path, float intensity) {
                if (!std::filesystem::exists(path)) throw FileNotFound("environment map not found: " + path);
                if (!std::filesystem::is_regular_file(path))  // a device or FIFO would hang the reader
                    throw SceneError("environment map '" + path + "' is not a regular file");
                Environment e;
                e.type = Environment::Type::Map;
                e.map_path = std::filesystem::absolute(path).string();
                e.intensity = intensity;
                return e;
            },
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

    py::class_<Camera>(m, "Camera", R"doc(
A pinhole camera, OpenGL conventions: right-handed world, y up, looking down the camera's -z.

position, target, up  world space
fov_y                 vertical field of view in degrees (0, 179)
near, far             clip distances along the view axis, 0 < near < far
The aspect ratio comes from the image (Settings.width / Settings.height).)doc")
        .def(py::init([](glm::vec3 position, glm::vec3 target, glm::vec3 up, float fov_y, float near_plane,
                         float far_plane) {
                 Camera c;
                 c.position = position;
                 c.target = target;
                 c.up = up;
                 c.fov_y_degrees = fov_y;
                 c.near_plane = near_plane;
                 c.far_plane = far_plane;
                 c.validate();
                 return c;
             }),
             py::arg("position") = glm::vec3(0, 0, 5), py::arg("target") = glm::vec3(0.0f),
             py::arg("up") = glm::vec3(0, 1, 0), py::arg("fov_y") = 60.0f, py::arg("near") = 0.1f,
             py::arg("far") = 100.0f)
        .def_readwrite("position", &Camera::position, "eye position, world space")
        .def_readwrite("target", &Camera::target, "point looked at, world space")
        .def_readwrite("up", &Camera::up, "world up direction (not parallel to the view direction)")
        .def_readwrite("fov_y", &Camera::fov_y_degrees, "vertical field of view, degrees in (0, 179)")
        .def_readwrite("near", &Camera::near_plane, "near clip distance along the view axis, > 0")
        .def_readwrite("far", &Camera::far_plane, "far clip distance along the view axis, > near")
        .def("view_matrix", &Camera::view, "World -> view matrix (4x4, row-major numpy).")
        .def(
            "projection_matrix",
            [](const Camera& c, float aspect, const std::string& depth_mode) {
                return c.projection(DepthConvention{parse_depth_mode(depth_mode)}, aspect);
            },
            py::arg("aspect"), py::arg("depth_mode") = "standard",
            "View -> clip matrix for this aspect ratio and depth convention.")
        .def("validate", &Camera::validate, "Raises ValueError naming the field if the camera is invalid.")
        .def(py::pickle(
            [](const Camera& c) {
                return py::make_tuple(c.position, c.target, c.up, c.fov_y_degrees, c.near_plane, c.far_plane);
            },
            [](py::tuple t) {
                Camera c;
                c.position = t[0].cast<glm::vec3>();
                c.target = t[1].cast<glm::vec3>();
                c.up = t[2].cast<glm::vec3>();
                c.fov_y_degrees = t[3].cast<float>();
                c.near_plane = t[4].cast<float>();
                c.far_plane = t[5].cast<float>();
                return c;
            }))
        .def("__repr__", [](const Camera& c) {
            auto v = [](const glm::vec3& x) {
                return "(" + std::to_string(x.x) + ", " + std::to_string(x.y) + ", " + std::to_string(x.z) + ")";
            };
            return "Camera(position=" + v(c.position) + ", target=" + v(c.target) + ", up=" + v(c.up) +
                   ", fov_y=" + std::to_string(c.fov_y_degrees) + ", near=" + std::to_string(c.near_plane) +
                   ", far=" + std::to_string(c.far_plane) + ")";
        });

    py::class_<Scene>(m, "Scene", py::dynamic_attr(), "The native scene; use ssrlab.Scene, which wraps it.")
        .def(py::init<>())
        .def_readwrite("name", &Scene::name, "the scene's name")
        .def_property_readonly("revision", &Scene::revision, "counts changes; GPU copies are refreshed when it moves")
        .def_property_readonly("geometry_revision", &Scene::geometry_revision,
                               "the revision of the last change that rebuilds GPU copies (geometry, images, objects "
                               "added, the environment map)")
        .def_property_readonly("transforms_revision", &Scene::transforms_revision,
                               "the revision of the last change of an object's transform or material index")
        .def_property_readonly("materials_revision", &Scene::materials_revision,
                               "the revision of the last change of a material's parameters")
        .def_property_readonly("lights_revision", &Scene::lights_revision, "the revision of the last change of the lights")
        .def_property_readonly("object_count", [](const Scene& s) { return s.objects.size(); }, "objects (mesh instances)")
        .def_property_readonly("mesh_count", [](const Scene& s) { return s.meshes.size(); }, "distinct meshes")
        .def_property_readonly("material_count", [](const Scene& s) { return s.materials.size(); }, "materials")
        .def_property_readonly("image_count", [](const Scene& s) { return s.images.size(); }, "texture images")
        .def("content_hash", [](const Scene& s) {
            char buf[17];
            std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(s.content_hash()));
            return std::string(buf);
        }, "A hex digest of everything that changes an image of the scene (cache key).")
        .def_property_readonly("triangle_count", &Scene::triangle_count,
                               "Triangles over all objects (an instanced mesh counts once per instance).")
        .def_property_readonly("bounds",
                               [](const Scene& s) {
                                   Bounds b = s.bounds();
                                   return py::make_tuple(b.min, b.max);
                               },
                               "world-space axis-aligned bounds ((min x, y, z), (max x, y, z))")
        .def_property(
            "ambient", [](const Scene& s) { return s.ambient; },
            [](Scene& s, glm::vec3 a) {
                if (const std::string p = radiance_problem(a, 1.0f); !p.empty())
                    throw std::invalid_argument("Scene.ambient " + p);
                s.ambient = a;
                s.touch_frame();
            },
            "ambient radiance, linear RGB >= 0, added to every surface's diffuse term")
        .def_property(
            "probes", [](const Scene& s) { return s.probes; },
            [](Scene& s, const std::vector<glm::vec3>& p) {
                for (size_t i = 0; i < p.size(); ++i)
                    if (!std::isfinite(p[i].x) || !std::isfinite(p[i].y) || !std::isfinite(p[i].z))
                        throw std::invalid_argument("Scene.probes: probe " + std::to_string(i) +
                                                    " must have finite coordinates");
                if (p.size() > 64) throw std::invalid_argument("Scene.probes: at most 64 probes, got " + std::to_string(p.size()));
                s.probes = p;
                s.touch_frame();
            },
            "reflection-probe positions (world space) for fallback 'probes'; each must lie inside the scene "
            "bounds (checked at render); empty: placed by Settings.probe_grid")
        .def_property(
            "environment", [](const Scene& s) { return s.environment; },
            [](Scene& s, const Environment& e) {
                // What each kind reads, scaled by its intensity (a map's texels are checked on load).
                std::vector<std::pair<const char*, glm::vec3>> terms = {{"intensity", glm::vec3(1.0f)}};
                if (e.type == Environment::Type::Constant) terms = {{"color", e.color}};
                if (e.type == Environment::Type::Sky)
                    terms = {{"zenith", e.sky_zenith}, {"horizon", e.sky_horizon}, {"ground", e.ground}};
                for (const auto& [name, rgb] : terms)
                    if (const std::string p = radiance_problem(rgb, e.intensity); !p.empty())
                        throw std::invalid_argument(std::string("Scene.environment: ") + name + " " + p);
                // Only a map is a texture of the scene's GPU copy; the rest is read per frame.
                const bool map = e.type == Environment::Type::Map || s.environment.type == Environment::Type::Map;
                const bool same_map = e.type == s.environment.type && e.map_path == s.environment.map_path;
                s.environment = e;
                if (map && !same_map) s.touch();
                else s.touch_frame();
            },
            "what the background and rays that leave the screen see")
        .def_property(
            "camera", [](const Scene& s) -> py::object {
                if (!s.camera) return py::none();
                return py::cast(Camera(*s.camera));
            },
            [](Scene& s, py::object c) {
                if (c.is_none()) s.camera.reset();
                else {
                    Camera cam = c.cast<Camera>();
                    cam.validate();
                    s.camera = static_cast<CameraDesc>(cam);
                }
                s.touch_frame();
            },
            "the scene's own camera (a copy), or None")
        .def(
            "_add_mesh",
            [](Scene& s, py::object positions, py::object indices, py::object normals, py::object uvs,
               py::object tangents, const Material& material, const glm::mat4& transform, const std::string& name,
               py::object colors, py::object uvs1) {
                Mesh mesh;
                mesh.name = name;
                mesh.positions = rows_of<float, 3>(positions, "positions");
                const size_t n = mesh.positions.size();
                if (!indices.is_none()) mesh.indices = indices_of(indices);
                if (!normals.is_none()) mesh.normals = rows_of<float, 3>(normals, "normals", n);
                if (!uvs.is_none()) mesh.uvs = rows_of<float, 2>(uvs, "uvs", n);
                if (!tangents.is_none()) mesh.tangents = rows_of<float, 4>(tangents, "tangents", n);
                if (!colors.is_none()) mesh.colors = rows_of<float, 4>(colors, "colors", n);
                if (!uvs1.is_none()) mesh.uvs1 = rows_of<float, 2>(uvs1, "uvs1", n);
                return add_mesh_object(s, std::move(mesh), material, transform, name);
            },
            py::arg("positions"), py::arg("indices"), py::arg("normals"), py::arg("uvs"), py::arg("tangents"),
            py::arg("material"), py::arg("transform"), py::arg("name"), py::arg("colors") = py::none(),
            py::arg("uvs1") = py::none())
        .def(
            "_add_primitive",
            [](Scene& s, const std::string& kind, const Material& material, const glm::mat4& transform,
               const std::string& name, float uv_tiles, int segments) {
                Mesh mesh;
                if (kind == "plane") mesh = make_plane(uv_tiles);
                else if (kind == "box") mesh = make_box();
                else if (kind == "sphere") mesh = make_sphere(std::max(segments, 3), std::max(segments / 2, 2));
                else throw std::invalid_argument("unknown primitive '" + kind + "'");
                const std::string object_name = name.empty() ? kind : name;
                mesh.name = object_name;
                return add_mesh_object(s, std::move(mesh), material, transform, object_name);
            },
            py::arg("kind"), py::arg("material"), py::arg("transform"), py::arg("name"), py::arg("uv_tiles") = 1.0f,
            py::arg("segments") = 48)
        .def(
            "_add_gltf",
            [](Scene& s, const std::string& path, const glm::mat4& transform, bool allow_external_files) {
                GltfLoadOptions options;
                options.allow_external_files = allow_external_files;
                std::vector<std::string> warnings;
                const int first = load_gltf(s, path, transform, options, &warnings);
                std::vector<int> ids;
                for (int i = first; i < int(s.objects.size()); ++i) ids.push_back(i);
                return py::make_tuple(ids, warnings);  // the Python wrapper emits the warnings
            },
            py::arg("path"), py::arg("transform"), py::arg("allow_external_files") = false)
        .def("_save", [](const Scene& s, const std::string& path, const std::string& folder) { save_gltf(s, path, folder); },
             py::arg("path"), py::arg("folder") = "")
        .def(
            "add_image",
            [](Scene& s, py::array_t<uint8_t, py::array::c_style | py::array::forcecast> rgba, const std::string& name) {
                if (rgba.ndim() != 3 || (rgba.shape(2) != 4 && rgba.shape(2) != 3))
                    throw std::invalid_argument("add_image: expected a uint8 array of shape (h, w, 3 or 4)");
                Image img;
                img.name = name;
                img.source = "<array>";
                img.height = int(rgba.shape(0));
                img.width = int(rgba.shape(1));
                const int c = int(rgba.shape(2));
                img.rgba.resize(size_t(img.width) * size_t(img.height) * 4);
                const uint8_t* p = rgba.data();
                for (size_t i = 0; i < size_t(img.width) * size_t(img.height); ++i)
                    for (int k = 0; k < 4; ++k) img.rgba[i * 4 + size_t(k)] = k < c ? p[i * size_t(c) + size_t(k)] : 255;
                s.images.push_back(std::move(img));
                s.touch();
                return int(s.images.size()) - 1;
            },
            py::arg("rgba"), py::arg("name") = "image",
            "Adds an 8-bit image (row 0 = top, uv (0,0) = top-left as in glTF); returns its index for Material textures.")
        .def(
            "image",
            [](const Scene& s, int i) {
                if (i < 0 || i >= int(s.images.size()))
                    throw std::out_of_range("Scene.image: index " + std::to_string(i) + " is out of range (the scene has " +
                                            std::to_string(s.images.size()) + " images)");
                const Image& img = s.images[size_t(i)];
                py::array_t<uint8_t> out({img.height, img.width, 4});
                std::memcpy(out.mutable_data(), img.rgba.data(), img.rgba.size());
                return out;
            },
            py::arg("index"), "A copy of image `index` as (h, w, 4) uint8 RGBA, row 0 = top.")
        .def(
            "load_image",
            [](Scene& s, const std::string& path) {
                s.images.push_back(decode_image_file(path));
                s.touch();
                return int(s.images.size()) - 1;
            },
            py::arg("path"), "Decodes an image file with OpenImageIO; returns its index for Material textures.")
        .def(
            "material",
            [](const Scene& s, int obj) {
                check_object(s, obj);
                return s.materials[size_t(s.objects[size_t(obj)].material)];
            },
            py::arg("object"), "A copy of an object's material.")
        .def(
            "set_material",
            [](Scene& s, int obj, const Material& m) {
                check_object(s, obj);
                validate_material(m, &s);
                int& idx = s.objects[size_t(obj)].material;
                int users = 0;
                for (const auto& o : s.objects) users += o.material == idx;
                if (users == 1) {  // only this object uses it
                    s.materials[size_t(idx)] = m;
                    s.touch_material(idx);
                } else {  // shared: give this object its own
                    idx = s.add_material(m);
                    s.touch_object(obj);
                }
            },
            py::arg("object"), py::arg("material"), "Gives an object a copy of `material` (others sharing its old one keep it).")
        .def(
            "object_name",
            [](const Scene& s, int obj) {
                check_object(s, obj);
                return s.objects[size_t(obj)].name;
            },
            py::arg("object"), "An object's name.")
        .def(
            "object_transform",
            [](const Scene& s, int obj) {
                check_object(s, obj);
                return s.objects[size_t(obj)].transform;
            },
            py::arg("object"), "An object's object -> world matrix (4x4).")
        .def(
            "set_object_transform",
            [](Scene& s, int obj, const glm::mat4& t) {
                check_object(s, obj);
                s.set_object_transform(obj, t);
            },
            py::arg("object"), py::arg("transform"),
            "Sets an object's object -> world matrix (4x4; ValueError naming the object when it is singular, "
            "not finite or reaches beyond the scene limits). The next render updates that object's matrix "
            "and its part of the BVH only.")
        .def(
            "object_mesh",
            [](const Scene& s, int obj) {
                check_object(s, obj);
                const Mesh& mesh = s.meshes[size_t(s.objects[size_t(obj)].mesh)];
                py::array_t<float> pos({py::ssize_t(mesh.positions.size()), py::ssize_t(3)});
                py::array_t<float> nrm({py::ssize_t(mesh.normals.size()), py::ssize_t(3)});
                py::array_t<uint32_t> idx({py::ssize_t(mesh.indices.size() / 3), py::ssize_t(3)});
                std::memcpy(pos.mutable_data(), mesh.positions.data(), mesh.positions.size() * 12);
                std::memcpy(nrm.mutable_data(), mesh.normals.data(), mesh.normals.size() * 12);
                std::memcpy(idx.mutable_data(), mesh.indices.data(), mesh.indices.size() * 4);
                py::dict d;
                d["name"] = mesh.name;
                d["positions"] = pos;
                d["normals"] = nrm;
                d["indices"] = idx;
                if (!mesh.uvs.empty()) {
                    py::array_t<float> uv({py::ssize_t(mesh.uvs.size()), py::ssize_t(2)});
                    std::memcpy(uv.mutable_data(), mesh.uvs.data(), mesh.uvs.size() * 8);
                    d["uvs"] = uv;
                }
                if (!mesh.uvs1.empty()) {
                    py::array_t<float> uv({py::ssize_t(mesh.uvs1.size()), py::ssize_t(2)});
                    std::memcpy(uv.mutable_data(), mesh.uvs1.data(), mesh.uvs1.size() * 8);
                    d["uvs1"] = uv;
                }
                if (!mesh.colors.empty()) {
                    py::array_t<float> c({py::ssize_t(mesh.colors.size()), py::ssize_t(4)});
                    std::memcpy(c.mutable_data(), mesh.colors.data(), mesh.colors.size() * 16);
                    d["colors"] = c;
                }
                return d;
            },
            py::arg("object"),
            "The object's mesh in object space: positions, normals, indices (m, 3), uvs, uvs1 and colors (RGBA).")
        .def_property_readonly("lights", [](const Scene& s) { return s.lights; }, "copies of the scene's lights")
        .def(
            "add_light",
            [](Scene& s, const Light& l) { return s.add_light(l); }, py::arg("light"),
            "Adds a copy of a light; returns its index.")
        .def("clear_lights",
             [](Scene& s) {
                 s.lights.clear();
                 for (SceneNode& n : s.nodes) n.light = -1;  // animated nodes carry no light any more
                 s.touch_lights();
             },
             "Removes every light.")
        .def(
            "_assign", [](Scene& s, const Scene& other) { s = other; }, py::arg("other"),
            "Makes this scene a deep copy of `other` (a different scene for GPU caches).");
}

void bind_io(py::module_& m) {
    m.def(
        "embree_intersect",
        [](const Scene& scene, py::array_t<float, py::array::c_style | py::array::forcecast> origins,
           py::array_t<float, py::array::c_style | py::array::forcecast> directions, float t_min, float t_max) {
            if (origins.ndim() != 2 || origins.shape(1) != 3 || directions.ndim() != 2 || directions.shape(1) != 3 ||
                origins.shape(0) != directions.shape(0))
                throw std::invalid_argument("embree_intersect: origins and directions must both have shape (n, 3)");
            const size_t n = size_t(origins.shape(0));
            std::vector<glm::vec3> o(n), d(n);
            std::memcpy(o.data(), origins.data(), n * 12);
            std::memcpy(d.data(), directions.data(), n * 12);
            // Embree asserts (aborting the process) on a NaN or Inf ray: refuse them here.
            for (size_t i = 0; i < n; ++i)
                if (!std::isfinite(o[i].x + o[i].y + o[i].z) || !std::isfinite(d[i].x + d[i].y + d[i].z) ||
                    glm::dot(d[i], d[i]) == 0.0f)
                    throw std::invalid_argument("embree_intersect: ray " + std::to_string(i) +
                                                " has a non-finite origin or direction, or a zero direction");
            if (!(t_min >= 0.0f) || !(t_max >= t_min))
                throw std::invalid_argument("embree_intersect: need 0 <= t_min <= t_max (t_max may be inf)");
            std::vector<CpuHit> hits;
            {
                py::gil_scoped_release release;
                hits = embree_intersect(scene, o, d, t_min, t_max);
            }
            const py::ssize_t count = py::ssize_t(n);
            py::array_t<float> t{count}, uv{{count, py::ssize_t(2)}};
            py::array_t<int32_t> obj{count}, prim{count};
            for (size_t i = 0; i < n; ++i) {
                t.mutable_at(i) = hits[i].t;
                obj.mutable_at(i) = hits[i].object;
                prim.mutable_at(i) = hits[i].primitive;
                uv.mutable_at(i, 0) = hits[i].u;
                uv.mutable_at(i, 1) = hits[i].v;
            }
            py::dict out;
            out["t"] = t;
            out["object"] = obj;
            out["primitive"] = prim;
            out["uv"] = uv;
            return out;
        },
        py::arg("scene"), py::arg("origins"), py::arg("directions"), py::arg("t_min") = 0.0f,
        py::arg("t_max") = 1e30f,
        "Closest hits of world-space rays with Intel Embree (robust mode), on the CPU: t (inf for a miss), "
        "object (-1 for a miss), primitive and Embree's barycentric uv. A production kernel to check the "
        "GPU reference tracer against.");

    m.def(
        "write_image",
        [](const std::string& path, py::array_t<float, py::array::c_style | py::array::forcecast> pixels,
           std::vector<std::string> channel_names, bool half) {
            if (pixels.ndim() != 3 && pixels.ndim() != 2)
                throw std::invalid_argument("write_image: pixels must have shape (h, w) or (h, w, c)");
            FloatImage img;
            img.height = int(pixels.shape(0));
            img.width = int(pixels.shape(1));
            img.channels = pixels.ndim() == 3 ? int(pixels.shape(2)) : 1;
            img.pixels.assign(pixels.data(), pixels.data() + pixels.size());
            if (!channel_names.empty() && int(channel_names.size()) != img.channels)
                throw std::invalid_argument("write_image: " + std::to_string(channel_names.size()) +
                                            " channel names for " + std::to_string(img.channels) + " channels");
            img.channel_names = std::move(channel_names);
            py::gil_scoped_release release;
            write_float_image(path, img, half);
        },
        py::arg("path"), py::arg("pixels"), py::arg("channel_names") = std::vector<std::string>{},
        py::arg("half") = false,
        "Writes float pixels with OpenImageIO (or ssrlab.io's Python codec); the extension picks the format (EXR keeps floats, "
        "PNG/JPEG get values clamped to [0, 1] and quantised to 8 bits).");
    m.def("image_io_backend", &image_io_backend,
          "Which library reads and writes image files: 'OpenImageIO', or 'python' in an extension built without "
          "it (ssrlab.io then reads and writes PNG and JPEG with Pillow, EXR with the OpenEXR package).");
    m.def(
        "_set_image_codec", [](py::object codec) { set_image_codec(codec.ptr()); }, py::arg("codec"),
        "Registers the Python image codec of an extension built without OpenImageIO (ssrlab.io does).");
    m.def(
        "read_image",
        [](const std::string& path) {
            FloatImage img;
            {
                py::gil_scoped_release release;
                img = read_float_image(path);
            }
            py::array_t<float> out({py::ssize_t(img.height), py::ssize_t(img.width), py::ssize_t(img.channels)});
            std::memcpy(out.mutable_data(), img.pixels.data(), img.pixels.size() * sizeof(float));
            return py::make_tuple(out, img.channel_names);
        },
        py::arg("path"), "Reads an image as float32 (h, w, c) and its channel names.");
}

}  // namespace ssr
