// Per-frame constants: the FrameUniforms uniform block (binding BUFFER_FRAME_UNIFORMS), read as
// frame.<name>.
// Generated when the Renderer starts from cpp/render/gpu_structs.def, where the C++ struct the
// host uploads is made from the same rows; ssrlab._core.gpu_struct_glsl() prints it.
#include "generated/FrameUniforms.glsl"
