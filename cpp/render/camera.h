// A pinhole camera with OpenGL conventions: right-handed world, y up, the camera looks down
// its local -z axis. Aspect comes from the image (Settings.width / Settings.height).
#pragma once

#include <glm/glm.hpp>

#include "render/depth_convention.h"
#include "scene/scene.h"

namespace ssr {

struct Camera : CameraDesc {
    Camera() = default;
    explicit Camera(const CameraDesc& d) : CameraDesc(d) {}

    void validate() const;  // throws std::invalid_argument naming the field
    glm::mat4 view() const;  // world -> view
    glm::mat4 projection(const DepthConvention& dc, float aspect) const;
};

}  // namespace ssr
