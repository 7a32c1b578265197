#include "render/depth_convention.h"

#include <cmath>
#include <stdexcept>

namespace ssr {

DepthMode parse_depth_mode(const std::string& name) {
    if (name == "standard") return DepthMode::Standard;
    if (name == "reversed_z") return DepthMode::ReversedZ;
    throw std::invalid_argument("depth_mode: expected 'standard' or 'reversed_z', got '" + name + "'");
}

std::string depth_mode_name(DepthMode m) { return m == DepthMode::Standard ? "standard" : "reversed_z"; }

glm::mat4 DepthConvention::projection(float fov_y, float aspect, float n, float f) const {
    const float g = 1.0f / std::tan(0.5f * fov_y);  // cot(fovY/2), the thesis's g
    glm::mat4 p(0.0f);
    p[0][0] = g / aspect;
    p[1][1] = g;
    p[2][3] = -1.0f;  // w_clip = -z_view
    if (mode == DepthMode::Standard) {
        // The thesis's P (seed 000, 2.3.4): rows 3 = ((f+n)/(n-f), 2fn/(n-f)).
        p[2][2] = (f + n) / (n - f);
        p[3][2] = 2.0f * f * n / (n - f);
    } else {
        // d = z_clip / w_clip = n/(f-n) * (f/z - 1) for view distance z: 1 at z = n, 0 at z = f.
        p[2][2] = n / (f - n);
        p[3][2] = f * n / (f - n);
    }
    return p;
}

void DepthConvention::apply_gl_state() const {
    glClipControl(GL_LOWER_LEFT, mode == DepthMode::Standard ? GL_NEGATIVE_ONE_TO_ONE : GL_ZERO_TO_ONE);
    glDepthFunc(compare());
    glClearDepthf(clear_depth());
}

void DepthConvention::add_defines(Defines& d) const {
    d["DEPTH_REVERSED_Z"] = mode == DepthMode::ReversedZ ? "1" : "0";
}

float DepthConvention::linearize(float d, float n, float f) const {
    if (mode == DepthMode::Standard) {
        // The thesis's 2fn / (z_s (f - n) - (f + n)), z_s = 2d - 1, rearranged without its
        // cancellation (as in shaders/lib/depth_convention.glsl).
        return f * n / (f * (1.0f - d) + n * d);
    }
    return f * n / (d * (f - n) + n);
}

}  // namespace ssr
