#version 450 core
// preintegrate (seed 002, 4.4.2 and Listing 4.4): the hierarchical pre-integrated visibility
// of every G-buffer layer, from the min-max Hi-Z. Level 0 is 1 where the layer covers the
// pixel and 0 where it does not. A coarser cell takes the mean visibility of its children
// (2x2, or up to 3x3 for the last cell of an odd-sized level, as hiz_build groups them) and
// modulates it by the share of the cell's depth slab that its children fill:
//     V_n = mean(V_(n-1) of the children) * (1 - empty share),
// the "percentage of empty space within the minimum and maximum of a depth cell" of 4.5.2.
// Depths are linearised to view space, as the listing does. Like the tracers' hit test, each
// child is solid from its min depth to its max depth plus Settings.thickness, so a
// continuous (even steep) surface leaves no gap and keeps its visibility, while a depth
// discontinuity (a silhouette in front of a far background) leaves empty volume that a cone
// sphere spanning the cell partly sees through. The factor is at most 1, so
// V_n <= mean(V_(n-1)) over the four (or more) finer cells at every cell: visibility only
// falls as the cone reads coarser levels (4.4.2). Listing 4.4 as printed multiplies each
// fine depth itself by 1 / (max - min), which is not a share; we take the gap lengths.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/ssr_settings.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(binding = IMAGE_VISIBILITY_LEVEL, r16f) writeonly uniform image2DArray o_level;

#if LEVEL0
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;  // g: coverage

void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(p.xy, imageSize(o_level).xy))) return;
    imageStore(o_level, p, vec4(texelFetch(u_material, p, 0).g > 0.5 ? 1.0 : 0.0));
}
#else
layout(binding = IMAGE_VISIBILITY_FINER, r16f) readonly uniform image2DArray u_finer;
layout(binding = IMAGE_HIZ_FINER, rg32f) readonly uniform image2DArray u_hiz_finer;   // (min s, max s)
layout(binding = IMAGE_HIZ_COARSE, rg32f) readonly uniform image2DArray u_hiz_coarse;

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    ivec2 size = imageSize(o_level).xy;
    if (any(greaterThanEqual(c.xy, size))) return;
    ivec2 finer = imageSize(u_finer).xy;
    ivec2 lo = 2 * c.xy;
    ivec2 hi = min(lo + 1, finer - 1);
    if (c.x == size.x - 1) hi.x = finer.x - 1;  // odd size: the last cell takes the third column/row
    if (c.y == size.y - 1) hi.y = finer.y - 1;

    // Children's solid intervals in view depth, and their mean visibility.
    float a[9], b[9];
    int n = 0, children = 0;
    float v_sum = 0.0;
    for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
            ++children;
            v_sum += imageLoad(u_finer, ivec3(x, y, c.z)).r;
            vec2 mm = imageLoad(u_hiz_finer, ivec3(x, y, c.z)).xy;
            if (mm.x > mm.y) continue;  // the layer covers nothing there
            float za = view_depth_of_screen(mm.x), zb = view_depth_of_screen(mm.y) + ssr.thickness;
            // insertion sort by the interval's front
            int k = n++;
            while (k > 0 && a[k - 1] > za) {
                a[k] = a[k - 1];
                b[k] = b[k - 1];
                --k;
            }
            a[k] = za;
            b[k] = zb;
        }
    float visibility = v_sum / float(children);
    vec2 cmm = imageLoad(u_hiz_coarse, c).xy;
    if (n > 0 && cmm.x <= cmm.y) {
        float front = view_depth_of_screen(cmm.x), back = view_depth_of_screen(cmm.y) + ssr.thickness;
        // Length of the union of the children's intervals = the filled part of the slab.
        float filled = 0.0, run_a = a[0], run_b = b[0];
        for (int k = 1; k < n; ++k) {
            if (a[k] > run_b) {
                filled += run_b - run_a;
                run_a = a[k];
                run_b = b[k];
            } else {
                run_b = max(run_b, b[k]);
            }
        }
        filled += run_b - run_a;
        float slab = back - front;
        float filled_share = slab > 0.0 ? clamp(filled / slab, 0.0, 1.0) : 1.0;
        visibility *= filled_share;
    }
    imageStore(o_level, c, vec4(visibility));
}
#endif
