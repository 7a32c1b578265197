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
    float zs = 2.0 * d - 1.0;
    return -2.0 * f * n / (zs * (f - n) - (f + n));
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
