// The Hi-Z tracer's own copy of the min-max pyramid (resource "hiz_trace", written by
// hiz_build next to the mip chain "hiz"). Two changes make each of the traversal's dependent
// fetches cheaper (seed 002, 4.7.2: the trace is fetch/latency bound):
//  - every level lies in ONE level-0 image (an atlas), so the tracer's texelFetch has lod 0 for
//    every lane. With a per-lane lod, llvmpipe gathers each lane's mip offset and strides (a
//    dependent texelFetch measured 2.5x slower with a lane-varying lod than with lod 0);
//  - a texel holds (min s, back s), back = the slab's back behind the cell's max, the depth the
//    slab test compares against (4.6.6), computed once per texel by the build rather than with
//    two divisions per traversal step. Where the max pyramid is off (Settings.hiz_use_max) a
//    coarse cell's back is EMPTY (the slab reaches to infinity, a min-only Hi-Z).
// A cell covering nothing holds (EMPTY, -EMPTY): no ray segment lies behind its min.
// Layout for a W x H image: level 0 at (0, 0); level l >= 1 at (W, H - (H >> (l - 1)) + l - 1),
// stacked to the right of level 0 (each level starts below the previous one's last row: the
// floor sizes sum to at most H - (H >> (l - 1)), and the + l - 1 keeps the 1-pixel-high tail
// levels apart). The atlas is (W + max(W >> 1, 1)) x (H + levels) texels; with the sight map
// (passes/hiz_build.comp's HIZ_SIGHT: the hybrid's walk, lib/screen_sight.glsl), W x H more
// texels at (0, H), under level 0, each the hull (lo, hi) in screen depth of the slabs of the
// surfaces beside the pixel that may reach into it ((EMPTY, -EMPTY) for none), and the atlas is
// max(H + levels, 2 H) texels high.
// Needs frame_uniforms, depth_convention and ssr_settings.

const float HIZ_EMPTY = 1e30;

ivec2 hiz_atlas_origin(int level) {
    ivec2 size = ivec2(frame.viewport.xy);
    return level == 0 ? ivec2(0) : ivec2(size.x, size.y - (size.y >> (level - 1)) + level - 1);
}

// Where the sight map starts: under level 0 (the coarser levels lie right of it).
ivec2 hiz_sight_origin() {
    return ivec2(0, int(frame.viewport.y));
}

// Levels of the full mip chain of the image: floor(log2(max(W, H))) + 1, GL's count.
int hiz_levels() {
    ivec2 size = ivec2(frame.viewport.xy);
    return findMSB(max(size.x, size.y)) + 1;
}

// The back of a surface slab: screen depth `thickness` behind screen depth s.
float hiz_slab_back(float s) {
    return screen_depth_of_view(view_depth_of_screen(s) + ssr.thickness);
}

// The atlas texel of a level-`level` cell whose covered pixels span screen depths [mn, mx].
vec2 hiz_atlas_texel(float mn, float mx, int level) {
    if (mn > mx) return vec2(HIZ_EMPTY, -HIZ_EMPTY);
    return vec2(mn, (level == 0 || ssr.hiz_use_max != 0) ? hiz_slab_back(mx) : HIZ_EMPTY);
}
