#version 450 core
// hiz_build (seed 002, 4.4.1 and 4.5.1): a min-max pyramid of screen depth per G-buffer
// layer. Level 0 holds (s, s) per covered pixel and (+inf, -inf) per empty one; each
// coarser cell holds the min and max of its children: 2x2, or up to 3x3 for the last cell
// of an odd-sized level, so that every level-0 pixel is covered at every level.
// With HIZ_TRACE_ATLAS each cell is also written, as the tracer reads it, into the atlas
// "hiz_trace" (lib/hiz_atlas.glsl).
// With HIZ_SIGHT (the hybrid's Hi-Z walk, fallback "bvh" with its confidence test:
// passes/hiz_build.cpp), level 0 also writes the sight map (lib/screen_sight.glsl,
// lib/hiz_atlas.glsl's hiz_sight_origin) and the pyramid's min is the sight map's: a coarse cell
// the walk skips is then in front of every surface its pixels show and of every edge beside them
// (a pixel's own min and max stay its sample's in the atlas's level 0, which the hit test reads).
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/ssr_settings.glsl"
#include "../lib/hiz_atlas.glsl"
#include "../lib/screen_sight.glsl"

#ifndef HIZ_SIGHT
#define HIZ_SIGHT 0
#endif

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(binding = IMAGE_HIZ_LEVEL, rg32f) writeonly uniform image2DArray o_level;
#if HIZ_TRACE_ATLAS
layout(binding = IMAGE_HIZ_TRACE, rg32f) writeonly uniform image2DArray o_atlas;
#endif
uniform int u_level;  // the level this dispatch writes

const float EMPTY = 1e30;

void store_cell(ivec3 c, vec2 mm) {
    imageStore(o_level, c, vec4(mm, 0.0, 0.0));
#if HIZ_TRACE_ATLAS
    vec2 texel = hiz_atlas_texel(mm.x, mm.y, u_level);
#if HIZ_SIGHT
    // A coarse cell whose pixels show nothing, beside an edge the sight map extends into it: its
    // slab reaches to infinity, so that a ray that reaches the edge's depth descends to the
    // pixels (which decide, lib/hiz_walk.glsl) rather than skipping the cell or being lost in it.
    if (mm.x > mm.y && mm.x < EMPTY) texel = vec2(mm.x, EMPTY);
#endif
    imageStore(o_atlas, ivec3(hiz_atlas_origin(u_level) + c.xy, c.z), vec4(texel, 0.0, 0.0));
#endif
}

#if HIZ_LEVEL0
layout(binding = TEXTURE_GBUFFER_DEPTH) uniform sampler2DArray u_depth;
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;  // g: coverage

#if HIZ_SIGHT
#include "../lib/input_fetch.glsl"
// View depths (lighting.comp: exactly the far plane where a layer is empty); by texelFetch, or by
// imageLoad (passes/hiz_build.cpp).
INPUT_ARRAY(u_linear_depth, TEXTURE_LINEAR_DEPTH, IMAGE_LINEAR_DEPTH, r32f);

// The 4 neighbour directions; the opposite of direction i is i ^ 1.
const ivec2 AROUND[4] = ivec2[4](ivec2(-1, 0), ivec2(1, 0), ivec2(0, -1), ivec2(0, 1));

// The sight map's view-depth interval at pixel p of `layer`: lib/screen_sight.glsl's rule 2
// toward each of the 4 neighbours n, the slabs [e, e + thickness] of the surfaces beside p that
// may reach into it at depth e (their hull); (0, 0) for none. None from n where p and n lie on one
// surface, however steeply it recedes (a floor seen far off changes by more than the thickness
// from pixel to pixel): p's sample on the continuation of n and the pixel beyond it, or n's on the
// continuation of the pixel behind p and p. Continuations are taken in 1/z, which is affine in
// screen space (w = 1/z: the next pixel's w is 2 w_b - w_a), and "on" is within SIGHT_EDGE pixel
// footprints of depth.
vec2 sight_slab(ivec2 p, int layer) {
    float far = frame.clip.y;
    // View depths along the 4 directions, 1 to 3 pixels out (0: empty, or off the image).
    float z[12], w[12];
    for (int i = 0; i < 12; ++i) {
        ivec2 q = p + (i / 4 + 1) * AROUND[i % 4];
        bool inside = all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, ivec2(frame.viewport.xy)));
        float v = FETCH(u_linear_depth, ivec3(clamp(q, ivec2(0), ivec2(frame.viewport.xy) - 1), layer)).r;
        z[i] = inside && v < far ? v : 0.0;
        w[i] = z[i] > 0.0 ? 1.0 / z[i] : 0.0;
    }
    float d = FETCH(u_linear_depth, ivec3(p, layer)).r;  // the far plane where the layer is empty
    bool covered = d < far;
    float wd = 1.0 / d;
    float tol = SIGHT_EDGE * 2.0 / (frame.proj[1][1] * frame.viewport.y);  // footprints per unit of depth
    float lo = 1e30, hi = 0.0;
    for (int i = 0; i < 4; ++i) {
        float dn = z[i], dn2 = z[4 + i], wn = w[i], wn2 = w[4 + i], wn3 = w[8 + i], wb = w[i ^ 1];
        float wc = wn2 > 0.0 ? 2.0 * wn - wn2 : 0.0;  // n's surface continued to p
        bool one = (wc > 0.0 && abs(wd - wc) <= tol * wc) ||
                   (wb > 0.0 && covered && abs(wn - (2.0 * wd - wb)) <= tol * (2.0 * wd - wb));
        // n's surface known to run on to p: n and the pixel beyond it within the thickness, or
        // the two beyond it on one line with n
        bool known = wc > 0.0 && (abs(dn - dn2) <= ssr.thickness ||
                                  (wn3 > 0.0 && abs(wn - (2.0 * wn2 - wn3)) <= tol * (2.0 * wn2 - wn3)));
        float e = 1e30;
        // 2a: n's surface continued in front of p's sample, where it runs on to p
        if (dn > 0.0 && !one && known && wd < (1.0 - tol) * wc) e = 1.0 / wc;
        // 2b: a surface beside p nearer than its sample by more than the thickness, not known to
        // turn away behind it (a concave crease: a floor running under a wall)
        if (dn > 0.0 && !one && !known && dn < d - ssr.thickness) e = dn;
        lo = min(lo, e);
        hi = max(hi, e < 1e30 ? e + ssr.thickness : 0.0);
    }
    return lo < 1e30 ? vec2(lo, hi) : vec2(0.0);
}
#endif

void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(p.xy, imageSize(o_level).xy))) return;
    bool covered = texelFetch(u_material, p, 0).g > 0.5;
    float s = screen_depth(texelFetch(u_depth, p, 0).r);
#if HIZ_SIGHT
    vec2 e = sight_slab(p.xy, p.z);
    vec2 es = e.x > 0.0 ? vec2(screen_depth_of_view(e.x), screen_depth_of_view(e.y)) : vec2(EMPTY, -EMPTY);
    // The pixel's own (min, max) in the atlas's level 0; in the pyramid, the min is the sight map's
    // too.
    imageStore(o_level, p, vec4(min(es.x, covered ? s : EMPTY), covered ? s : -EMPTY, 0.0, 0.0));
    imageStore(o_atlas, ivec3(hiz_atlas_origin(0) + p.xy, p.z), vec4(covered ? hiz_atlas_texel(s, s, 0) : vec2(EMPTY, -EMPTY), 0.0, 0.0));
    imageStore(o_atlas, ivec3(hiz_sight_origin() + p.xy, p.z), vec4(es, 0.0, 0.0));
#else
    store_cell(p, covered ? vec2(s, s) : vec2(EMPTY, -EMPTY));
#endif
}
#else
layout(binding = IMAGE_HIZ_FINER, rg32f) readonly uniform image2DArray u_finer;

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    ivec2 size = imageSize(o_level).xy;
    if (any(greaterThanEqual(c.xy, size))) return;
    ivec2 finer = imageSize(u_finer).xy;
    ivec2 lo = 2 * c.xy;
    ivec2 hi = min(lo + 1, finer - 1);
    if (c.x == size.x - 1) hi.x = finer.x - 1;  // odd width: the last cell takes the third column
    if (c.y == size.y - 1) hi.y = finer.y - 1;
    vec2 mm = vec2(EMPTY, -EMPTY);
    for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
            vec2 f = imageLoad(u_finer, ivec3(x, y, c.z)).xy;
            mm = vec2(min(mm.x, f.x), max(mm.y, f.y));
        }
    store_cell(c, mm);
}
#endif
