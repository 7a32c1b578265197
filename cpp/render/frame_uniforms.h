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
    glm::mat4 view_to_shadow;  // the first 2D-mapped caster's view -> shadow-map texture space (Frame.shadow_matrix;
                               // the shaders read each light's own, GpuLight::view_to_shadow)
    glm::vec4 viewport;        // (width, height, 1/width, 1/height) in pixels
    glm::vec4 clip;            // (near, far, layers, light count)
    glm::vec4 ambient;         // rgb constant ambient radiance
    glm::vec4 shadow;          // (enabled, the first caster's texel world size, normal offset in texels, pcf radius)
    glm::vec4 env_params;      // (type: 0 constant, 1 sky, 2 map; intensity; 0; 0)
    glm::vec4 env_color;       // rgb constant environment radiance
    glm::vec4 env_zenith;      // rgb sky radiance straight up
    glm::vec4 env_horizon;     // rgb sky radiance at the horizon
    glm::vec4 env_ground;      // rgb radiance below the horizon
    // Motion vectors (Settings.motion_vectors): this frame's world -> clip without the TAA jitter,
    // and the previous frame's of the sequence (this frame's where there is none).
    glm::mat4 view_proj_unjittered;
    glm::mat4 previous_view_proj;
};
static_assert(sizeof(FrameUniforms) == 7 * 64 + 9 * 16, "std140 layout of FrameUniforms");
constexpr int kPreviousModelsBinding = 31;  // SSBO: each object's model matrix in the previous frame

// std430 element of the lights buffer, in view space.
struct GpuLight {
    glm::vec4 position_type;     // xyz position (point) ; w = 0 directional, 1 point, 2 spot
    glm::vec4 direction_shadow;  // xyz direction light travels (directional) ; w = 1 casts a shadow
    glm::vec4 radiance;          // rgb = colour * intensity
    glm::vec4 cone;              // x, y: spot angle scale, offset (0, 1: no cone); z: 1 / range^2 (0: no range)
    // Its shadow map (passes/shadow_map.h): x the layer of `shadow_map` (directional, spot) or -1;
    // y the cube of `shadow_cubes` (point) or -1; a layer: z the world size of one texel at the
    // scene's centre; a cube: z, w the faces' near and far planes.
    glm::vec4 shadow;
    // A layer: view -> its texture space [0,1]^3 (divide by w). A cube: view -> world axes
    // centred on the light (the cube map's lookup vector).
    glm::mat4 view_to_shadow;
};
static_assert(sizeof(GpuLight) == 9 * 16, "std430 layout of GpuLight");

}  // namespace ssr
