// What save_gltf writes in the default scene's extras.ssrlab: the ambient term, the scene's name,
// its camera and its environment, which glTF has no field for.

#include "scene/gltf_reader.h"
#include "scene/image_io.h"
#include "scene/scene_limits.h"

namespace ssr::gltf_detail {

void read_scene_extras(const tinygltf::Model& model, const GltfReader& r, Scene& scene, const PathPolicy& pol,
                       const std::string& path) {
    if (!model.scenes.empty()) {
        const auto& extras = model.scenes[size_t(model.defaultScene >= 0 ? model.defaultScene : 0)].extras;
        if (extras.Has("ssrlab")) {
            const auto& x = extras.Get("ssrlab");
            const std::string w = "scene extras.ssrlab";
            if (!x.IsObject()) r.fail(w + " is not an object");
            if (x.Has("ambient")) scene.ambient = vec3_from_value(x.Get("ambient"), scene.ambient, r, w + ".ambient", 0.0, kMaxRadiance);
            if (x.Has("name")) scene.name = string_from_value(x.Get("name"), r, w + ".name");
            if (x.Has("camera")) {
                const auto& c = x.Get("camera");
                const std::string cw = w + ".camera";
                if (!c.IsObject()) r.fail(cw + " is not an object");
                CameraDesc cam = scene.camera.value_or(CameraDesc{});
                cam.position = vec3_from_value(c.Get("position"), cam.position, r, cw + ".position",
                                               -kMaxWorldCoordinate, kMaxWorldCoordinate);
                cam.target = vec3_from_value(c.Get("target"), cam.target, r, cw + ".target",
                                             -kMaxWorldCoordinate, kMaxWorldCoordinate);
                cam.up = vec3_from_value(c.Get("up"), cam.up, r, cw + ".up");
                if (c.Has("fov_y")) cam.fov_y_degrees = float(number_from_value(c.Get("fov_y"), r, cw + ".fov_y", 1e-4, 179.9));
                if (c.Has("near")) cam.near_plane = float(number_from_value(c.Get("near"), r, cw + ".near", 1e-30, 1e30));
                if (c.Has("far")) cam.far_plane = float(number_from_value(c.Get("far"), r, cw + ".far", 0.0, 1e30));
                if (!usable_direction(cam.target - cam.position)) r.fail(cw + ": target equals position");
                if (!usable_direction(glm::cross(cam.target - cam.position, cam.up)))
                    r.fail(cw + ": up is zero or parallel to the view direction");
                if (cam.far_plane > 0.0f && !(cam.far_plane > cam.near_plane)) r.fail(cw + ": far must be greater than near");
                scene.camera = cam;
            }
            if (x.Has("environment")) {
                const auto& e = x.Get("environment");
                const std::string ew = w + ".environment";
                if (!e.IsObject()) r.fail(ew + " is not an object");
                Environment env;
                const std::string type = e.Has("type") ? string_from_value(e.Get("type"), r, ew + ".type") : "constant";
                if (type != "constant" && type != "sky" && type != "map")
                    r.fail(ew + ".type '" + type + "' is not constant, sky or map");
                env.type = type == "sky" ? Environment::Type::Sky : type == "map" ? Environment::Type::Map : Environment::Type::Constant;
                env.color = vec3_from_value(e.Get("color"), env.color, r, ew + ".color", 0.0, kMaxRadiance);
                env.sky_zenith = vec3_from_value(e.Get("zenith"), env.sky_zenith, r, ew + ".zenith", 0.0, kMaxRadiance);
                env.sky_horizon = vec3_from_value(e.Get("horizon"), env.sky_horizon, r, ew + ".horizon", 0.0, kMaxRadiance);
                env.ground = vec3_from_value(e.Get("ground"), env.ground, r, ew + ".ground", 0.0, kMaxRadiance);
                if (e.Has("intensity")) env.intensity = float(number_from_value(e.Get("intensity"), r, ew + ".intensity", 0.0, kMaxRadiance));
                if (env.type == Environment::Type::Map) {
                    if (!e.Has("map")) r.fail(ew + ": type 'map' without a 'map' path");
                    const std::string ref = string_from_value(e.Get("map"), r, ew + ".map");
                    // Checked now, not when the renderer reads it: a device or FIFO would hang the reader.
                    env.map_path = resolve_reference(pol, ref, "environment map").string();
                    probe_image_file(env.map_path, path + ": environment map");
                }
                scene.environment = env;
            }
        }
    }
}

}  // namespace ssr::gltf_detail
