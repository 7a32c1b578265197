#version 450 core
// Readback: copies one level of a texture into a storage buffer as vec4 per texel, every
// layer, rows flipped so that row 0 is the top of the image (numpy's convention; GL's
// row 0 is the bottom). Fetching through a sampler also decodes sRGB storage to linear.
// Used for normalised, sRGB and depth formats only: float textures are downloaded as stored
// and flipped on the CPU (Renderer::read_texture; 3-5x less time per byte on llvmpipe,
// benchmarks/timing/readback.py).

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

#if READ_ARRAY
layout(binding = TEXTURE_SOURCE) uniform sampler2DArray u_source;
#else
layout(binding = TEXTURE_SOURCE) uniform sampler2D u_source;
#endif
uniform int u_level;
uniform ivec2 u_size;

layout(std430, binding = BUFFER_TEXELS) writeonly buffer Texels { vec4 texels[]; };

void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID);
    if (p.x >= u_size.x || p.y >= u_size.y) return;
#if READ_ARRAY
    vec4 v = texelFetch(u_source, p, u_level);
#else
    vec4 v = texelFetch(u_source, p.xy, u_level);
#endif
    int row = u_size.y - 1 - p.y;
    texels[(p.z * u_size.y + row) * u_size.x + p.x] = v;
}
