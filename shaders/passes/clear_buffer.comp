#version 450 core
// Gives u_count uints of a storage buffer from uint u_first the value u_value by stores
// (passes/compute.h, clear_uints; storage binding BUFFER_CLEAR_TARGET, which no other shader
// declares): the buffer clears of the list constructions' heads where FrameContext::clear_by_compute
// says so. On an
// H200 a buffer clear ran at 31 GB/s where compute stores reached 1.6 TB/s
// (benchmarks/gpu-results/nvidia-h200-pcie-sse2/visibility_raster_floor_1920x1080.txt: clear.heads,
// stores). Groups in rows of at most 65535 (the dispatch's x limit).
layout(local_size_x = 256, local_size_y = 1, local_size_z = 1) in;

layout(std430, binding = BUFFER_CLEAR_TARGET) writeonly buffer ClearTarget { uint clear_target[]; };
uniform uint u_first;
uniform uint u_count;
uniform uint u_value;

void main() {
    uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 256u + gl_LocalInvocationID.x;
    if (i < u_count) clear_target[u_first + i] = u_value;
}
