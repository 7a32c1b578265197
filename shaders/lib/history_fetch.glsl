// Fetching a history texture at a reprojected position (shaders/lib/reprojection.glsl gives the
// position; the including pass supplies the texture). Pure function.

// Bilinear fetch of `history` at window position `pos` (pixels, centres at .5), clamped to the
// edge: the reprojected position of a moving camera falls between the previous pixels.
vec4 history_bilinear(sampler2D history, vec2 pos, ivec2 size) {
    vec2 t = pos - 0.5;
    ivec2 b = ivec2(floor(t));
    vec2 f = t - vec2(b);
    vec4 c00 = texelFetch(history, clamp(b, ivec2(0), size - 1), 0);
    vec4 c10 = texelFetch(history, clamp(b + ivec2(1, 0), ivec2(0), size - 1), 0);
    vec4 c01 = texelFetch(history, clamp(b + ivec2(0, 1), ivec2(0), size - 1), 0);
    vec4 c11 = texelFetch(history, clamp(b + ivec2(1, 1), ivec2(0), size - 1), 0);
    return mix(mix(c00, c10, f.x), mix(c01, c11, f.x), f.y);
}
