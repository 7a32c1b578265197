#version 450 core
// Device peaks for the roofline (benchmarks/timing/roofline.py): small kernels that each
// stress one resource a render pass uses, through the same GL context and the same texture
// formats as the frame. Renderer::microbenchmark dispatches one invocation per texel of a
// width x height grid and `u_iterations` operations per invocation, and times it; the work is
// counted on the host from these definitions (one "operation" each):
//   KERNEL_INIT        fills u_source (RGBA16F array) and u_chain (RG32F) with their content
//   KERNEL_COHERENT    texelFetch of RG32F texels (the Hi-Z pyramid's format) at addresses known
//                      up front, neighbouring invocations fetching neighbouring texels
//   KERNEL_DEPENDENT   texelFetch whose coordinate is the previous fetch's result (pointer
//                      chasing within a few pixels, as a tracer's next cell depends on the depth
//                      it just fetched: seed 002 4.7.2); latency-bound
//   KERNEL_DEPENDENT_IMAGE  the same chain by imageLoad of the same texture (lib/input_fetch.glsl:
//                      llvmpipe's texelFetch of a float format is a call to a generic sampling
//                      function, imageLoad is inline; the passes read float inputs by imageLoad
//                      on the CPU device)
//   KERNEL_STORE       imageStore of RGBA16F texels (a G-buffer or ray output)
//   KERNEL_BANDWIDTH   texelFetch of distinct RGBA32F texels, each read once (16 bytes each):
//                      streaming read bandwidth
//   KERNEL_COPY        one RGBA16F texelFetch and one RGBA32F imageStore per texel: a trivial
//                      full-frame pass, the floor any full-screen pass pays (composite's formats)
//   KERNEL_COPY_IMAGE  the same copy reading by imageLoad (the composite's path on the CPU device)
// Every kernel's result reaches memory (o_sink), so no fetch can be optimised away.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = TEXTURE_SOURCE) uniform sampler2DArray u_source;   // RGBA16F, u_layers layers
layout(binding = TEXTURE_CHAIN) uniform sampler2D u_chain;         // RG32F: the next texel to fetch (pixels)
layout(binding = TEXTURE_WIDE) uniform sampler2DArray u_wide;     // RGBA32F, u_iterations layers (bandwidth)

#if KERNEL_INIT
layout(binding = IMAGE_INIT_SOURCE, rgba16f) writeonly uniform image2DArray o_source;
layout(binding = IMAGE_INIT_CHAIN, rg32f) writeonly uniform image2D o_chain;
layout(binding = IMAGE_INIT_WIDE, rgba32f) writeonly uniform image2DArray o_wide;
#elif KERNEL_STORE
layout(binding = IMAGE_STORE, rgba16f) writeonly uniform image2DArray o_store;  // u_layers layers
#else
layout(binding = IMAGE_SINK, rgba32f) writeonly uniform image2D o_sink;
#endif
#if KERNEL_DEPENDENT_IMAGE
layout(binding = IMAGE_CHAIN, rg32f) readonly uniform image2D i_chain;  // u_chain as an image
#elif KERNEL_COPY_IMAGE
layout(binding = IMAGE_SOURCE, rgba16f) readonly uniform image2DArray i_source;  // u_source as an image
#endif

uniform int u_iterations;
uniform int u_layers;

uint hash(uint x) {
    x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15; x *= 0x846ca68bu; x ^= x >> 16;
    return x;
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = textureSize(u_chain, 0);
    if (p.x >= size.x || p.y >= size.y) return;
#if KERNEL_INIT
    for (int l = 0; l < u_layers; ++l) imageStore(o_source, ivec3(p, l), vec4(p, l, 1.0) * 1e-3);
    for (int l = 0; l < u_iterations; ++l) imageStore(o_wide, ivec3(p, l), vec4(p, l, 1.0) * 1e-3);
    // The next texel: within +-4 pixels, as a tracer's next cell is near its current one.
    uint h = hash(uint(p.x) * 73856093u ^ uint(p.y) * 19349663u);
    ivec2 next = clamp(p + ivec2(int(h & 7u) - 4, int((h >> 3) & 7u) - 4), ivec2(0), size - 1);
    imageStore(o_chain, p, vec4(vec2(next), 0.0, 0.0));
#elif KERNEL_COHERENT
    // The dependent kernel's texture and texel count, with addresses known up front: every
    // invocation walks the same offsets, so a wavefront fetches a contiguous block.
    vec2 sum = vec2(0.0);
    for (int i = 0; i < u_iterations; ++i) {
        ivec2 q = clamp(p + ivec2(i & 7, (i >> 3) & 7) - 4, ivec2(0), size - 1);
        sum += texelFetch(u_chain, q, 0).xy;
    }
    imageStore(o_sink, p, vec4(sum, 0.0, 1.0));
#elif KERNEL_DEPENDENT
    vec2 q = vec2(p);
    for (int i = 0; i < u_iterations; ++i) q = texelFetch(u_chain, ivec2(q), 0).xy;
    imageStore(o_sink, p, vec4(q, 0.0, 1.0));
#elif KERNEL_DEPENDENT_IMAGE
    vec2 q = vec2(p);
    for (int i = 0; i < u_iterations; ++i) q = imageLoad(i_chain, ivec2(q)).xy;
    imageStore(o_sink, p, vec4(q, 0.0, 1.0));
#elif KERNEL_STORE
    for (int i = 0; i < u_iterations; ++i) imageStore(o_store, ivec3(p, i % u_layers), vec4(float(i), p, 1.0));
#elif KERNEL_BANDWIDTH
    vec4 sum = vec4(0.0);
    for (int i = 0; i < u_iterations; ++i) sum += texelFetch(u_wide, ivec3(p, i), 0);
    imageStore(o_sink, p, sum);
#elif KERNEL_COPY
    imageStore(o_sink, p, texelFetch(u_source, ivec3(p, 0), 0));
#elif KERNEL_COPY_IMAGE
    imageStore(o_sink, p, imageLoad(i_source, ivec3(p, 0)));
#endif
}
