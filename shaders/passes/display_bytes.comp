#version 450 core
// Display bytes: a float colour texture as the 8-bit sRGB codes the live viewer's page gets
// (ssrlab.Frame.srgb8), packed as the host's (height, width, 3) uint8 array is (rows top first,
// R G B per pixel, four pixels in three uints, little-endian). Downloading the float colour and
// encoding it on the CPU moves 16 bytes a pixel and runs the transfer function per channel in
// numpy; this moves 3 and runs where the pixels are.
//
// Which code a value gets is decided by the host: for each code k = 1..255 it passes the smallest
// float32 linear value that ssrlab.io.linear_to_srgb and to_bytes take to k or more
// (ssrlab.io.srgb8_thresholds), and a channel's code is how many of them lie at or below its
// value, exposed and clamped to [0, 1] as ssrlab.io.linear_to_srgb does it: the codes numpy gives,
// bit for bit, on any device whose float multiply is IEEE's. The transfer function below only
// finds the bracket to start from.

layout(local_size_x = 256, local_size_y = 1, local_size_z = 1) in;

layout(binding = TEXTURE_SOURCE) uniform sampler2D u_source;
uniform ivec2 u_size;
uniform float u_exposure;
uniform float u_thresholds[255];

layout(std430, binding = BUFFER_DISPLAY_BYTES) writeonly buffer DisplayBytes { uint words[]; };

// numpy.nan_to_num's float32 value (NaN 0, infinities the largest finite values), decided on the
// bits so that no compiler's assumption about NaN can fold it away.
float finite_value(float x) {
    uint b = floatBitsToUint(x);
    if ((b & 0x7F800000u) != 0x7F800000u) return x;
    if ((b & 0x007FFFFFu) != 0u) return 0.0;
    return uintBitsToFloat((b & 0x80000000u) | 0x7F7FFFFFu);
}

// How many thresholds lie at or below y: the transfer function's code, as near as this device's
// pow gives it, moved to the code whose thresholds bracket y (at most a step either way where pow
// rounds differently from numpy's).
uint code_of(float linear) {
    float y = clamp(finite_value(linear) * u_exposure, 0.0, 1.0);
    float srgb = y <= 0.0031308 ? 12.92 * y : 1.055 * pow(y, 1.0 / 2.4) - 0.055;
    int k = clamp(int(srgb * 255.0 + 0.5), 0, 255);
    while (k > 0 && y < u_thresholds[k - 1]) --k;
    while (k < 255 && u_thresholds[k] <= y) ++k;
    return uint(k);
}

// The codes of pixel i of the image read top row first (0 past its end), as R | G << 8 | B << 16.
uint pixel_codes(int i) {
    if (i >= u_size.x * u_size.y) return 0u;
    ivec2 p = ivec2(i % u_size.x, u_size.y - 1 - i / u_size.x);
    vec3 c = texelFetch(u_source, p, 0).rgb;
    return code_of(c.r) | (code_of(c.g) << 8) | (code_of(c.b) << 16);
}

void main() {
    // Four pixels per invocation: 12 bytes, 3 words. Dispatched in rows of work groups (a GPU
    // allows at most 65535 along one axis).
    int quad = int(gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x);
    if (quad * 4 >= u_size.x * u_size.y) return;
    uint a = pixel_codes(quad * 4), b = pixel_codes(quad * 4 + 1), c = pixel_codes(quad * 4 + 2),
         d = pixel_codes(quad * 4 + 3);
    words[quad * 3] = a | (b << 24);
    words[quad * 3 + 1] = (b >> 8) | (c << 16);
    words[quad * 3 + 2] = (c >> 16) | (d << 8);
}
