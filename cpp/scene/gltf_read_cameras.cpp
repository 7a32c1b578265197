// Cameras (glTF 2.0, cameras): perspective ones are read, orthographic ones skipped.

#include <glm/gtc/matrix_transform.hpp>

#include "scene/gltf_reader.h"
#include "scene/scene_limits.h"

namespace ssr::gltf_detail {

void check_cameras(const tinygltf::Model& model, const GltfReader& r, std::vector<std::string>& warnings,
                   const std::string& file) {
    for (size_t i = 0; i < model.cameras.size(); ++i) {
        const auto& c = model.cameras[i];
        const std::string what = "camera " + std::to_string(i);
        if (c.type == "perspective") {
            const auto& p = c.perspective;
            if (!in_range(p.yfov, 1e-6, 3.14159)) r.fail(what + ": yfov " + num(p.yfov) + " is not an angle in (0, pi) radians");
            if (!in_range(p.znear, 1e-30, 1e30) || !(float(p.znear) > 0.0f)) r.fail(what + ": znear " + num(p.znear) + " must be finite and > 0");
            if (p.zfar != 0.0 && (!in_range(p.zfar, 0.0, 1e30) || !(float(p.zfar) > float(p.znear))))
                r.fail(what + ": zfar " + num(p.zfar) + " must be finite and greater than znear " + num(p.znear));
            if (!in_range(p.aspectRatio, 0.0, 1e6)) r.fail(what + ": aspectRatio " + num(p.aspectRatio) + " must be finite and >= 0");
        } else if (c.type == "orthographic") {
            warnings.push_back(file + ": " + what + " is orthographic; only perspective cameras are used, it was skipped");
        } else {
            r.fail(what + ": type '" + c.type + "' is neither perspective nor orthographic");
        }
    }
}

void read_node_camera(const tinygltf::Model& model, const GltfReader& r, const tinygltf::Node& node,
                      const glm::mat4& world, const std::string& what, Scene& scene) {
    if (node.camera >= int(model.cameras.size()) || node.camera < -1)
        r.fail(what + ": camera index " + std::to_string(node.camera) + " is out of range (the file has " +
               std::to_string(model.cameras.size()) + " cameras)");
    if (node.camera >= 0 && !scene.camera && model.cameras[size_t(node.camera)].type == "perspective") {
        const auto& pc = model.cameras[size_t(node.camera)].perspective;
        const glm::vec3 back(world[2]), up(world[1]);
        if (!usable_direction(back) || !usable_direction(up) || !usable_direction(glm::cross(back, up)))
            r.fail(what + ": camera " + std::to_string(node.camera) + "'s node transform is degenerate (no view direction)");
        CameraDesc cam;
        cam.position = glm::vec3(world[3]);
        if (!within_world(cam.position))
            r.fail(what + ": camera " + std::to_string(node.camera) + " stands beyond +-" + num(kMaxWorldCoordinate) +
                   " in world space");
        // glTF cameras look down -z; the target far enough away to differ in float from the position.
        const float reach = std::max(1.0f, 1e-3f * glm::length(cam.position));
        cam.target = cam.position - glm::normalize(back) * reach;
        cam.up = glm::normalize(up);
        cam.fov_y_degrees = float(glm::degrees(pc.yfov));
        cam.near_plane = float(pc.znear);
        cam.far_plane = pc.zfar > pc.znear ? float(pc.zfar) : 0.0f;  // 0: fitted to the scene later
        scene.camera = cam;
    }
}

void fit_infinite_far_plane(Scene& scene, const GltfReader& r) {
    if (scene.camera && scene.camera->far_plane <= 0.0f) {
        const Bounds bb = scene.bounds();
        float reach = 1.0f;
        for (int i = 0; i < 8; ++i) {
            const glm::vec3 corner((i & 1) ? bb.max.x : bb.min.x, (i & 2) ? bb.max.y : bb.min.y, (i & 4) ? bb.max.z : bb.min.z);
            reach = std::max(reach, glm::length(corner - scene.camera->position));
        }
        if (!std::isfinite(reach) || reach > 1e30f) r.fail("the scene is too large to fit an infinite camera's far plane");
        scene.camera->far_plane = 1.5f * reach;
        if (!(scene.camera->far_plane > scene.camera->near_plane)) scene.camera->far_plane = scene.camera->near_plane * 2.0f;
    }
}

}  // namespace ssr::gltf_detail
