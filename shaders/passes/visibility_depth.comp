#version 450 core
// visibility_buffer depth store (deep_gbuffer "visibility_lists" peeling a frame whose fragments
// exceed Settings.deep_gbuffer_budget): layer u_layer of gbuffer.depth, an R32F array with this
// construction (the selection stores its depths by compute, passes/visibility_select.comp), from
// the depth target that layer was rasterised into: the window depth as the depth test kept it,
// bit for bit.
#include "../lib/frame_uniforms.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = TEXTURE_VISIBILITY_BUFFER_RASTER_DEPTH) uniform sampler2D u_raster_depth;
layout(binding = IMAGE_GBUFFER_DEPTH, r32f) writeonly uniform image2DArray o_depth;

uniform int u_layer;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(frame.viewport.x) || p.y >= int(frame.viewport.y)) return;
    imageStore(o_depth, ivec3(p, u_layer), vec4(texelFetch(u_raster_depth, p, 0).r));
}
