#version 450 core
// Gives layers [u_first, u_first + gl_NumWorkGroups.z) of one level of a layered image a
// constant value by image stores (passes/compute.h, clear_layers). On GPUs built for compute
// (NVIDIA's H100 and H200 have few raster units), glClearTexSubImage and framebuffer clears run at
// about a tenth of the memory bandwidth a compute shader's stores reach. Not for render targets:
// there the first image store into a new texture cost far more (passes/depth_peel.cpp).
// IMAGE_FORMAT: the image's format qualifier (rgba16f, r32f, rgba8, ...).
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

#if IMAGE_ARRAY
layout(binding = IMAGE_TARGET, IMAGE_FORMAT) writeonly uniform image2DArray o_image;
#else
layout(binding = IMAGE_TARGET, IMAGE_FORMAT) writeonly uniform image2D o_image;
#endif
uniform vec4 u_value;
uniform ivec2 u_size;
uniform int u_first;

void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID.xy, int(gl_GlobalInvocationID.z) + u_first);
    if (p.x >= u_size.x || p.y >= u_size.y) return;
#if IMAGE_ARRAY
    imageStore(o_image, p, u_value);
#else
    imageStore(o_image, p.xy, u_value);
#endif
}
