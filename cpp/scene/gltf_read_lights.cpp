// Punctual lights (KHR_lights_punctual): directional, point and spot, placed by their nodes.

#include "scene/gltf_reader.h"
#include "scene/scene_limits.h"

namespace ssr::gltf_detail {

void check_lights(const tinygltf::Model& model, const GltfReader& r) {
    for (size_t i = 0; i < model.lights.size(); ++i) {
        const auto& l = model.lights[i];
        const std::string what = "light " + std::to_string(i) + " ('" + l.name + "')";
        if (l.type != "directional" && l.type != "point" && l.type != "spot")
            r.fail(what + ": type '" + l.type + "' is not directional, point or spot");
        if (!l.color.empty() && l.color.size() != 3) r.fail(what + ": color does not have 3 values");
        double peak = 1.0;
        if (!l.color.empty()) {
            peak = 0.0;
            for (double x : l.color) {
                if (!in_range(x, 0.0, kMaxLightPower)) r.fail(what + ": color holds " + num(x) + ", outside [0, " + num(kMaxLightPower) + "]");
                peak = std::max(peak, x);
            }
        }
        if (!in_range(l.intensity, 0.0, kMaxLightPower))
            r.fail(what + ": intensity " + num(l.intensity) + " is outside [0, " + num(kMaxLightPower) + "]");
        if (peak * l.intensity > kMaxLightPower)
            r.fail(what + ": color x intensity " + num(peak * l.intensity) + " is more than " + num(kMaxLightPower) +
                   " (the half-float lighting buffers would overflow)");
        if (l.range != 0.0 && !in_range(l.range, 1e-30, 1e30)) r.fail(what + ": range " + num(l.range) + " must be finite and > 0");
        if (l.type == "spot") {
            if (!in_range(l.spot.innerConeAngle, 0.0, 1.5708) || !in_range(l.spot.outerConeAngle, 1e-6, 1.5708) ||
                !(l.spot.innerConeAngle < l.spot.outerConeAngle))
                r.fail(what + ": spot cone angles must satisfy 0 <= innerConeAngle < outerConeAngle <= pi/2");
        }
    }
}

int read_node_light(const tinygltf::Model& model, const GltfReader& r, const tinygltf::Node& node,
                    const glm::mat4& world, const std::string& what, Scene& scene) {
    if (auto it = node.extensions.find("KHR_lights_punctual"); it != node.extensions.end() && it->second.Has("light")) {
        const auto& lv = it->second.Get("light");
        if (!lv.IsInt() && !lv.IsNumber()) r.fail(what + ": KHR_lights_punctual.light is not an index");
        const double ld = lv.GetNumberAsDouble();
        if (!(ld >= 0.0 && ld < double(model.lights.size())) || ld != std::floor(ld))
            r.fail(what + ": light index " + num(ld) + " is out of range (the file has " +
                   std::to_string(model.lights.size()) + " lights)");
        const int li = int(ld);
        const auto& gl = model.lights[size_t(li)];
        const std::string lwhat = "light " + std::to_string(li);
        Light l;
        l.name = gl.name;
        l.color = vec3_from(gl.color, glm::vec3(1.0f));
        l.intensity = float(gl.intensity);
        l.position = glm::vec3(world[3]);
        if (!within_world(l.position))
            r.fail(what + ": light " + std::to_string(li) + " stands beyond +-" + num(kMaxWorldCoordinate) +
                   " in world space");
        const glm::vec3 dir = -glm::vec3(world[2]);
        if (gl.type == "directional") {
            l.type = Light::Type::Directional;
            l.cast_shadow = true;
        } else {
            l.type = gl.type == "spot" ? Light::Type::Spot : Light::Type::Point;
            l.inner_cone = float(gl.spot.innerConeAngle);
            l.outer_cone = float(gl.spot.outerConeAngle);
            l.range = float(gl.range);
            // KHR_lights_punctual has no shadow flag: directional and spot lights cast one by
            // default (a layer of the 2D shadow maps each), point lights none unless
            // extras.cast_shadow asks (a cube map: six draws of the scene, six times the
            // memory, so not on by default for the many point lights a file may hold).
            l.cast_shadow = l.type == Light::Type::Spot;
        }
        if (gl.extras.Has("cast_shadow")) {
            if (!gl.extras.Get("cast_shadow").IsBool()) r.fail(lwhat + ": extras.cast_shadow is not a boolean");
            l.cast_shadow = gl.extras.Get("cast_shadow").Get<bool>();
        }
        const bool explicit_dir = gl.extras.Has("direction");
        l.direction = explicit_dir ? vec3_from_value(gl.extras.Get("direction"), dir, r, lwhat + ": extras.direction") : dir;
        if (gl.extras.Has("position"))
            l.position = vec3_from_value(gl.extras.Get("position"), l.position, r, lwhat + ": extras.position",
                                         -kMaxWorldCoordinate, kMaxWorldCoordinate);
        if (l.type != Light::Type::Point && !usable_direction(l.direction))
            r.fail(explicit_dir ? lwhat + ": extras.direction is a zero vector"
                                : what + ": light " + std::to_string(li) + " has no direction (its node's transform is degenerate)");
        l.direction = usable_direction(l.direction) ? glm::normalize(l.direction) : glm::vec3(0.0f, -1.0f, 0.0f);
        const int light = scene.add_light(l);
        return light;
    }
    return -1;
}

}  // namespace ssr::gltf_detail
