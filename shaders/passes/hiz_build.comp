#version 450 core
// hiz_build (seed 002, 4.4.1 and 4.5.1): a min-max pyramid of screen depth per G-buffer
// layer. Level 0 holds (s, s) per covered pixel and (+inf, -inf) per empty one; each
// coarser cell holds the min and max of its children: 2x2, or up to 3x3 for the last cell
// of an odd-sized level, so that every level-0 pixel is covered at every level.
// With HIZ_TRACE_ATLAS each cell is also written, as the tracer reads it, into the atlas
// "hiz_trace" (lib/hiz_atlas.glsl).
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/ssr_settings.glsl"
#include "../lib/hiz_atlas.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(binding = 0, rg32f) writeonly uniform image2DArray o_level;
#if HIZ_TRACE_ATLAS
layout(binding = 2, rg32f) writeonly uniform image2DArray o_atlas;
#endif
uniform int u_level;  // the level this dispatch writes

void store_cell(ivec3 c, vec2 mm) {
    imageStore(o_level, c, vec4(mm, 0.0, 0.0));
#if HIZ_TRACE_ATLAS
    imageStore(o_atlas, ivec3(hiz_atlas_origin(u_level) + c.xy, c.z), vec4(hiz_atlas_texel(mm.x, mm.y, u_level), 0.0, 0.0));
#endif
}

const float EMPTY = 1e30;

#if HIZ_LEVEL0
layout(binding = 0) uniform sampler2DArray u_depth;
layout(binding = 1) uniform sampler2DArray u_material;  // g: coverage

void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(p.xy, imageSize(o_level).xy))) return;
    bool covered = texelFetch(u_material, p, 0).g > 0.5;
    float s = screen_depth(texelFetch(u_depth, p, 0).r);
    store_cell(p, covered ? vec2(s, s) : vec2(EMPTY, -EMPTY));
}
#else
layout(binding = 1, rg32f) readonly uniform image2DArray u_finer;

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
