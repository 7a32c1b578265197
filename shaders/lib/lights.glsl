// Punctual lights in view space: the LightData records of storage buffer 3, read as lights[i].
// Generated when the Renderer starts from cpp/render/gpu_structs.def, with the C++ struct the
// host uploads (GpuLight); ssrlab._core.gpu_struct_glsl() prints it.
#include "generated/Lights.glsl"

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
