// Punctual lights in view space (storage buffer 3). Mirrors GpuLight in
// cpp/render/frame_uniforms.h.

struct LightData {
    vec4 position_type;     // xyz position (point); w = 0 directional, 1 point
    vec4 direction_shadow;  // xyz direction light travels (directional); w = 1 casts the shadow map
    vec4 radiance;          // rgb colour * intensity
};

layout(std430, binding = 3) readonly buffer Lights { LightData lights[]; };
