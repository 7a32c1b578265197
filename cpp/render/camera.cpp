#include "render/camera.h"

#include "scene/scene_limits.h"

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <stdexcept>

namespace ssr {

namespace {
bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
}  // namespace

void Camera::validate() const {
    if (!finite3(position)) throw std::invalid_argument("Camera.position must be finite");
    if (!finite3(target)) throw std::invalid_argument("Camera.target must be finite");
    if (const std::string p = world_point_problem(position); !p.empty()) throw std::invalid_argument("Camera.position " + p);
    if (const std::string p = world_point_problem(target); !p.empty()) throw std::invalid_argument("Camera.target " + p);
    if (!finite3(up) || glm::length(up) < 1e-6f) throw std::invalid_argument("Camera.up must be a non-zero finite vector");
    const glm::vec3 fwd = target - position;
    if (glm::length(fwd) < 1e-6f) throw std::invalid_argument("Camera.target must differ from Camera.position");
    if (glm::length(glm::cross(glm::normalize(fwd), glm::normalize(up))) < 1e-4f)
        throw std::invalid_argument("Camera.up must not be parallel to the viewing direction");
    if (!(fov_y_degrees > 0.0f && fov_y_degrees < 179.0f))
        throw std::invalid_argument("Camera.fov_y must be in (0, 179) degrees, got " + std::to_string(fov_y_degrees));
    if (!(near_plane > 0.0f) || !std::isfinite(near_plane))
        throw std::invalid_argument("Camera.near must be > 0, got " + std::to_string(near_plane));
    if (!(far_plane > near_plane) || !std::isfinite(far_plane))
        throw std::invalid_argument("Camera.far must be finite and > Camera.near, got near=" + std::to_string(near_plane) +
                                    " far=" + std::to_string(far_plane));
}

glm::mat4 Camera::view() const { return glm::lookAt(position, target, up); }

glm::mat4 Camera::projection(const DepthConvention& dc, float aspect) const {
    return dc.projection(glm::radians(fov_y_degrees), aspect, near_plane, far_plane);
}

}  // namespace ssr
