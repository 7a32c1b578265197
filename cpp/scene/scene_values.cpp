// The values a scene holds, made and checked the same way for every caller: the Python bindings
// forward to these, so a C++ caller meets the same domains and the same messages.

#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "core/errors.h"
#include "scene/scene.h"
#include "scene/scene_limits.h"

namespace ssr {

void check_alpha_cutoff(float cutoff) {
    if (!(cutoff >= 0.0f && std::isfinite(cutoff)))
        throw std::invalid_argument("Material.alpha_cutoff must be finite and >= 0, got " + std::to_string(cutoff));
}

void check_emissive(const glm::vec3& emissive) {
    if (const std::string p = radiance_problem(emissive, 1.0f); !p.empty())
        throw std::invalid_argument("Material.emissive " + p);
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
    check_alpha_cutoff(m.alpha_cutoff);
    check_emissive(m.emissive);
    if (scene) {
        for (const TextureRef* t : {&m.base_color_texture, &m.metallic_roughness_texture, &m.normal_texture,
                                    &m.emissive_texture, &m.specular_texture, &m.specular_color_texture})
            if (t->image >= int(scene->images.size()))
                throw std::invalid_argument("Material texture refers to image " + std::to_string(t->image) +
                                            ", but the scene has " + std::to_string(scene->images.size()) + " images");
    }
}

Light directional_light(const glm::vec3& direction, const glm::vec3& color, float intensity, bool cast_shadow,
                        const std::string& name) {
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
}

Light point_light(const glm::vec3& position, const glm::vec3& color, float intensity, const std::string& name) {
    if (!(intensity >= 0.0f)) throw std::invalid_argument("Light.intensity must be >= 0");
    Light l;
    l.type = Light::Type::Point;
    l.position = position;
    l.color = color;
    l.intensity = intensity;
    l.name = name;
    return l;
}

Light spot_light(const glm::vec3& position, const glm::vec3& direction, float inner_cone, float outer_cone,
                 const glm::vec3& color, float intensity, float range, const std::string& name) {
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
}

Environment environment_map(const std::string& path, float intensity) {
    if (!std::filesystem::exists(path)) throw FileNotFound("environment map not found: " + path);
    if (!std::filesystem::is_regular_file(path))  // a device or FIFO would hang the reader
        throw SceneError("environment map '" + path + "' is not a regular file");
    Environment e;
    e.type = Environment::Type::Map;
    e.map_path = std::filesystem::absolute(path).string();
    e.intensity = intensity;
    return e;
}

}  // namespace ssr
