// Texture look-ups without bound samplers, for passes that shade surfaces of any material in
// one dispatch (the reference tracer): every scene image as RGBA8 texels in one storage
// buffer, sampled at level 0 with bilinear filtering and the texture's wrap modes, sRGB
// decoded before filtering as GL does.

layout(std430, binding = BUFFER_IMAGE_TEXELS) readonly buffer ImageTexels { uint image_texels[]; };  // RGBA8, rows top-first
layout(std430, binding = BUFFER_IMAGE_INFO) readonly buffer ImageInfo { ivec4 image_info[]; };     // (first texel, width, height, 0)

const int WRAP_REPEAT = 10497, WRAP_CLAMP = 33071, WRAP_MIRRORED = 33648;  // glTF / GL enums

// i mod n in [0, n) for any sign of i: GLSL leaves % undefined when an operand is negative
// (GLSL 4.50 5.9), so negative coordinates are folded with non-negative operands only.
int floor_mod(int i, int n) {
    return i >= 0 ? i % n : (n - 1) - ((-(i + 1)) % n);
}

int wrap_coordinate(int i, int n, int mode) {
    if (mode == WRAP_CLAMP) return clamp(i, 0, n - 1);
    if (mode == WRAP_MIRRORED) {
        int period = 2 * n;
        int j = floor_mod(i, period);
        return j < n ? j : period - 1 - j;
    }
    return floor_mod(i, n);
}

vec3 srgb_to_linear(vec3 c) {
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));
}

vec4 image_texel(int image, int x, int y, bool srgb) {
    ivec4 info = image_info[image];
    vec4 v = unpackUnorm4x8(image_texels[info.x + y * info.y + x]);
    if (srgb) v.rgb = srgb_to_linear(v.rgb);
    return v;
}

// wraps: wrap_s | (wrap_t << 16)
vec4 sample_image(int image, vec2 uv, int wraps, bool srgb) {
    if (image < 0) return vec4(1.0);
    ivec4 info = image_info[image];
    int ws = wraps & 0xffff, wt = wraps >> 16;
    vec2 x = uv * vec2(info.yz) - 0.5;
    ivec2 i0 = ivec2(floor(x));
    vec2 f = x - vec2(i0);
    int x0 = wrap_coordinate(i0.x, info.y, ws), x1 = wrap_coordinate(i0.x + 1, info.y, ws);
    int y0 = wrap_coordinate(i0.y, info.z, wt), y1 = wrap_coordinate(i0.y + 1, info.z, wt);
    vec4 top = mix(image_texel(image, x0, y0, srgb), image_texel(image, x1, y0, srgb), f.x);
    vec4 bottom = mix(image_texel(image, x0, y1, srgb), image_texel(image, x1, y1, srgb), f.x);
    return mix(top, bottom, f.y);
}
