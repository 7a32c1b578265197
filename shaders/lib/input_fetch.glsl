// How a pass reads its float inputs texel by texel: by texelFetch from a sampler, or,
// with FETCH_BY_IMAGE (the renderer defines it for every pass: 1 on the CPU device, 0 on a GPU;
// Renderer.info["input_fetch"]), by imageLoad from a read-only image of the same texture.
// Why: llvmpipe (Mesa 22.3) samples any texture whose format is not 8-bit RGBA through a call to
// a generic sampling function, which addresses each lane's mip level on its own (even for lod
// 0), and the caller saves its live vector registers around every call; imageLoad is inline. A
// chain of dependent RG32F fetches ran 1.9x faster by imageLoad (benchmarks/timing/roofline.py's
// "dependent" and "dependent_image" kernels), and a perf profile of the Hi-Z walk showed the
// call and its per-lane mip addressing as the largest part of each step. GPUs keep texelFetch,
// the path measured there. 8-bit formats (sRGB albedo, material) stay samplers: inline already,
// and an image would not decode sRGB.
// Declare an input with one of the INPUT_* macros (name, texture unit, image unit, format
// qualifier of the texture's format), the units by name, and read it with FETCH(name, texel):
//     INPUT_ARRAY(u_normal, TEXTURE_GBUFFER_NORMAL, IMAGE_GBUFFER_NORMAL, rgba16f);
// The pass binds the texture to the texture unit (texelFetch) or the image unit (imageLoad:
// passes/compute.h, NamedUnits::fetch), and both read level 0.

#ifndef FETCH_BY_IMAGE
#define FETCH_BY_IMAGE 0
#endif

#if FETCH_BY_IMAGE
#define INPUT_ARRAY(name, texture_unit, image_unit, format) \
    layout(binding = image_unit, format) readonly uniform image2DArray name
#define INPUT_2D(name, texture_unit, image_unit, format) \
    layout(binding = image_unit, format) readonly uniform image2D name
#define FETCH(name, texel) imageLoad(name, texel)
#else
#define INPUT_ARRAY(name, texture_unit, image_unit, format) layout(binding = texture_unit) uniform sampler2DArray name
#define INPUT_2D(name, texture_unit, image_unit, format) layout(binding = texture_unit) uniform sampler2D name
#define FETCH(name, texel) texelFetch(name, texel, 0)
#endif
