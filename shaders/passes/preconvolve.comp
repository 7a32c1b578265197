#version 450 core
// preconvolve (seed 002, 4.4.4 and 4.5.4): a mip chain of each lit G-buffer layer for the
// glossy methods. Level 0 holds (lit * coverage, coverage): colour premultiplied by coverage,
// so that every later blur and downsample, and the cone tracer's trilinear fetches, average
// covered pixels only; an uncovered pixel adds 0 to both sums and bleeds nothing (the colour
// of a texel is rgb / a). Each coarser level is the level below blurred by the chapter's
// normalised separable 7-tap Gaussian, then reduced to GL's mip size, one axis per dispatch:
// AXIS 0 blurs level n-1 along x and reduces its width into the scratch texture, AXIS 1
// blurs the scratch along y and reduces its height into level n.
//
// Energy: both steps keep the image's sum (times the area ratio), so every level's
// coverage-weighted mean colour, sum(rgb) / sum(a), equals level 0's:
//  - the blur uses half-sample symmetric borders (pixel -1 reads pixel 0, -2 reads 1, ...):
//    a symmetric kernel over the mirrored, periodic image moves energy but never loses it
//    (clamp-to-edge would weight border pixels more than others);
//  - the reduction is an exact box resampling: output texel i covers the input interval
//    [i r, (i + 1) r) with r = size_in / size_out, partial texels by their overlap. For even
//    sizes this is the 2x2 mean; for odd ones (5 -> 2: r = 2.5) the middle input texel is
//    split between its two output texels, so no texel counts more than another and the
//    mean is kept exactly, where folding it into the last texel would weight it 1.5x.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = IMAGE_PRECONVOLVE_DST, rgba32f) writeonly uniform image2DArray o_dst;

#if LEVEL0
layout(binding = TEXTURE_LIT) uniform sampler2DArray u_lit;
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;  // g: coverage

void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(p.xy, imageSize(o_dst).xy))) return;
    float coverage = texelFetch(u_material, p, 0).g > 0.5 ? 1.0 : 0.0;
    imageStore(o_dst, p, vec4(texelFetch(u_lit, p, 0).rgb * coverage, coverage));
}
#else
layout(binding = IMAGE_PRECONVOLVE_SRC, rgba32f) readonly uniform image2DArray u_src;
uniform ivec2 u_src_size;  // the region of u_src that holds the input
uniform ivec2 u_dst_size;  // the region of o_dst written

// The chapter's weights (4.5.4: 0.001, 0.028, 0.233, 0.474, ...) sum to 0.998; divided by
// their sum so that the blur keeps energy exactly, as the chapter intends.
const float GAUSS[4] = float[4](0.474 / 0.998, 0.233 / 0.998, 0.028 / 0.998, 0.001 / 0.998);

// Half-sample symmetric border: ... 1 0 | 0 1 2 ... n-1 | n-1 n-2 ...
// (Reflected until inside: GLSL leaves % of negative numbers undefined, and levels of one or
// two texels need more than one reflection for a 7-tap kernel.)
int mirror_index(int i, int n) {
    for (int k = 0; k < 8 && (i < 0 || i >= n); ++k) i = i < 0 ? -1 - i : 2 * n - 1 - i;
    return i;
}

vec4 fetch(int i, int other, int layer) {
#if AXIS == 0
    return imageLoad(u_src, ivec3(mirror_index(i, u_src_size.x), other, layer));
#else
    return imageLoad(u_src, ivec3(other, mirror_index(i, u_src_size.y), layer));
#endif
}

vec4 blurred(int i, int other, int layer) {
    vec4 c = GAUSS[0] * fetch(i, other, layer);
    for (int k = 1; k <= 3; ++k) c += GAUSS[k] * (fetch(i - k, other, layer) + fetch(i + k, other, layer));
    return c;
}

void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(p.xy, u_dst_size))) return;
#if AXIS == 0
    int n_in = u_src_size.x, n_out = u_dst_size.x, i = p.x, other = p.y;
#else
    int n_in = u_src_size.y, n_out = u_dst_size.y, i = p.y, other = p.x;
#endif
    // Exact box resampling of the blurred row: output texel i covers [a, b) of the input.
    float r = float(n_in) / float(n_out);
    float a = float(i) * r, b = float(i + 1) * r;
    vec4 sum = vec4(0.0);
    for (int j = int(floor(a)); j < int(ceil(b)); ++j) {
        float overlap = min(float(j + 1), b) - max(float(j), a);
        if (overlap > 0.0) sum += overlap * blurred(j, other, p.z);
    }
    imageStore(o_dst, p, sum / r);
}
#endif
