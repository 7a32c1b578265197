// Punctual lights in view space (storage buffer 3). Mirrors GpuLight in
// cpp/render/frame_uniforms.h.

struct LightData {
    vec4 position_type;     // xyz position (point, spot); w = 0 directional, 1 point, 2 spot
    vec4 direction_shadow;  // xyz direction light travels (directional); w = 1 casts a shadow
    vec4 radiance;          // rgb colour * intensity
    vec4 cone;              // x, y: spot angle scale, offset (0, 1: no cone); z: 1 / range^2 (0: none)
    vec4 shadow;            // x layer of the 2D maps or -1; y cube or -1; z texel size (layer) or near, w far (cube)
    mat4 view_to_shadow;    // layer: view -> its texture space; cube: view -> world axes about the light
};

layout(std430, binding = 3) readonly buffer Lights { LightData lights[]; };

// The renderer compiles the scene's light count into every pass (LIGHT_COUNT, for up to 8
// lights), and every pass that shades calls lights_load() first in main, before any control flow,
// to read every light once: llvmpipe (Mesa 22.3) loads a storage-buffer value inside a loop, an if
// or after a return one lane and one component at a time through the stack, which was ~30 % of the
// lighting pass (a perf profile, `hall` at the thesis configuration). The shading reads LIGHT_AT(i)
// for i < LIGHTS_IN_FRAME either way.
#ifdef LIGHT_COUNT
LightData g_lights[LIGHT_COUNT > 0 ? LIGHT_COUNT : 1];
void lights_load() {
    for (int i = 0; i < LIGHT_COUNT; ++i) g_lights[i] = lights[i];
}
#define LIGHT_AT(i) g_lights[i]
#define LIGHTS_IN_FRAME LIGHT_COUNT
#else
void lights_load() {}
#define LIGHT_AT(i) lights[i]
#define LIGHTS_IN_FRAME int(frame.clip.w)  // the frame's light count
#endif
