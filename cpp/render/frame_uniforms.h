// Per-frame constants shared by every pass (uniform buffer binding 0, std140).
// Mirrored field by field in shaders/lib/frame_uniforms.glsl: change both together.
#pragma once

#include <glm/glm.hpp>

namespace ssr {

constexpr int kFrameUniformsBinding = 0;  // UBO
constexpr int kObjectsBinding = 1;        // SSBO: per-object transforms and material index
constexpr int kMaterialsBinding = 2;      // SSBO: material factors
constexpr int kLightsBinding = 3;         // SSBO: lights in view space

struct FrameUniforms {
    glm::mat4 view;            // world -> view
    glm::mat4 inv_view;        // view -> world
    glm::mat4 proj;            // view -> clip (depth convention of the frame)
    glm::mat4 inv_proj;        // clip -> view
    glm::mat4 view_to_shadow;  // view -> shadow-map texture space [0,1]^3
    glm::vec4 viewport;        // (width, height, 1/width, 1/height) in pixels
    glm::vec4 clip;            // (near, far, layers, light count)
    glm::vec4 ambient;         // rgb constant ambient radiance
    glm::vec4 shadow;          // (enabled, world size of one shadow texel, normal offset in texels, pcf radius)
    glm::vec4 env_params;      // (type: 0 constant, 1 sky, 2 map; intensity; 0; 0)
    glm::vec4 env_color;       // rgb constant environment radiance
    glm::vec4 env_zenith;      // rgb sky radiance straight up
    glm::vec4 env_horizon;     // rgb sky radiance at the horizon
    glm::vec4 env_ground;      // rgb radiance below the horizon
};
static_assert(sizeof(FrameUniforms) == 5 * 64 + 9 * 16, "std140 layout of FrameUniforms");

// std430 element of the lights buffer, in view space.
struct GpuLight {
    glm::vec4 position_type;     // xyz position (point) ; w = 0 directional, 1 point
    glm::vec4 direction_shadow;  // xyz direction light travels (directional) ; w = 1 casts the shadow map
    glm::vec4 radiance;          // rgb = colour * intensity
    glm::vec4 cone;              // x, y: spot angle scale, offset (0, 1: no cone); z: 1 / range^2 (0: no range)
};

}  // namespace ssr
