#version 450 core
// A second pass over the rays, after the trace: keeps every ray's hit (u_keep = 1) or drops it
// (u_keep = 0, a miss: zeros). Reads[0] is the copy of rays.hit taken before it runs (every ray
// layer); writes[0], rays.hit, at image unit 0. Dispatch "ray": 8x8 trace pixels of one ray layer
// per group (gl_WorkGroupID.z).
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2DArray u_hit;
layout(rgba32f, binding = 0) writeonly uniform image2DArray o_hit;

uniform bool u_keep;

void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID.xy, gl_WorkGroupID.z);
    if (any(greaterThanEqual(p.xy, imageSize(o_hit).xy))) return;
    imageStore(o_hit, p, u_keep ? texelFetch(u_hit, p, 0) : vec4(0.0));
}
