#version 450 core
// deep_gbuffer write: layer u_layer of the G-buffer from the fragments the selection kept
// (passes/deep_gbuffer_select.comp). The stored outputs go through the same framebuffer
// formats (sRGB encoding, half floats, unorm8) as peeling's shading pass, and the stored window
// depth is written as the fragment depth, so every texel equals the peeled one bit for bit.
// Every pixel is written (the clear values where the layer holds no fragment): no discard, and
// no clear before it. The covered tiles were marked by the selection.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/fragment_lists.glsl"

layout(std430, binding = BUFFER_KEPT_FRAGMENTS) readonly buffer KeptFragments { uint kept[]; };

uniform int u_layer;

layout(location = 0) out vec4 o_albedo_metallic;
layout(location = 1) out vec4 o_normal_roughness;
layout(location = 2) out vec4 o_material;
#if EMISSION_TEXTURE
layout(location = 3) out vec4 o_emission;
#endif
#if SPECULAR_TEXTURE
layout(location = 3 + EMISSION_TEXTURE) out vec4 o_specular;
#endif
#if MOTION_VECTORS
layout(location = 3 + EMISSION_TEXTURE + SPECULAR_TEXTURE) out vec4 o_motion;
#endif

void main() {
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 p = ivec2(gl_FragCoord.xy);
    uint s = kept[uint(u_layer) * uint(size.x * size.y) + uint(p.y * size.x + p.x)];
    if (s == FRAGMENT_NONE) {
        o_albedo_metallic = vec4(0.0);
        o_normal_roughness = vec4(0.0);
        o_material = vec4(0.0);
#if EMISSION_TEXTURE
        o_emission = vec4(0.0);
#endif
#if SPECULAR_TEXTURE
        o_specular = vec4(0.0);
#endif
#if MOTION_VECTORS
        o_motion = vec4(0.0);
#endif
        gl_FragDepth = DEPTH_CLEAR;
        return;
    }
    o_albedo_metallic = fragments[s].albedo_metallic;
    o_normal_roughness = fragments[s].normal_roughness;
    o_material = fragments[s].material;
#if EMISSION_TEXTURE
    o_emission = fragments[s].emission;
#endif
#if SPECULAR_TEXTURE
    o_specular = fragments[s].specular;
#endif
#if MOTION_VECTORS
    o_motion = fragments[s].motion;
#endif
    gl_FragDepth = fragments[s].depth;
}
