// The shader half of cpp/render/depth_convention.h: window depth <-> view-space depth and
// the "strictly farther" test, for the standard and the reversed-Z conventions.
// DEPTH_REVERSED_Z is defined (0 or 1) by the renderer; needs frame_uniforms.glsl.

#if DEPTH_REVERSED_Z
const float DEPTH_CLEAR = 0.0;
#else
const float DEPTH_CLEAR = 1.0;
#endif

// Positive view-space depth (distance along the viewing axis) of window depth d.
float linear_depth(float d) {
    float n = frame.clip.x, f = frame.clip.y;
#if DEPTH_REVERSED_Z
    return f * n / (d * (f - n) + n);
#else
    // Seed 000, 2.3.4: z = 2fn / (z_s (f - n) - (f + n)) with z_s = 2d - 1 in NDC; z < 0.
    // Written as fn / (f (1 - d) + n d), the same value: the seed's form subtracts two numbers
    // near f (f+n and z_s (f-n)) and loses all digits for large f/n (at f/n = 1e8 it
    // doubled the depth error, and a covered-nothing d = 1 gave 0/0 once f - n rounded to f);
    // 1 - d is exact near 1 (Sterbenz), so only the stored depth's own precision is left.
    return f * n / (f * (1.0 - d) + n * d);
#endif
}

// True when window depth a lies strictly behind window depth b.
bool is_farther(float a, float b) {
#if DEPTH_REVERSED_Z
    return a < b;
#else
    return a > b;
#endif
}

// View-space position of the point at positive view depth z seen through `pixel`
// (window coordinates in pixels, pixel centres at .5), for any perspective projection
// (offsets in proj[2].xy, e.g. a TAA jitter, included).
vec3 view_position(vec2 pixel, float z) {
    vec2 ndc = pixel * frame.viewport.zw * 2.0 - 1.0;
    vec2 xy = (ndc + vec2(frame.proj[2][0], frame.proj[2][1])) * z / vec2(frame.proj[0][0], frame.proj[1][1]);
    return vec3(xy, -z);
}

// "Screen depth" s: window depth with its sign chosen so that s grows with distance in both
// conventions (s = d standard, s = -d reversed-Z; negation keeps every bit of precision).
// s is affine in 1/z, so it interpolates linearly in screen space (seed 002, 4.4.3): the
// Hi-Z pyramid and its traversal work in s.
float screen_depth(float d) {
#if DEPTH_REVERSED_Z
    return -d;
#else
    return d;
#endif
}

float screen_depth_of_view(float z) {
    float ndc = (frame.proj[2][2] * -z + frame.proj[3][2]) / z;
#if DEPTH_REVERSED_Z
    return -ndc;  // window depth = ndc with glClipControl ZERO_TO_ONE
#else
    return ndc * 0.5 + 0.5;
#endif
}

float view_depth_of_screen(float s) {
#if DEPTH_REVERSED_Z
    return linear_depth(-s);
#else
    return linear_depth(s);
#endif
}
