#version 450 core
// trace_hiz: the hierarchical min-max traversal (seed 002, 4.4.3 and 4.5.3) over every G-buffer
// layer; the walk itself is lib/hiz_walk.glsl, which a user trace pass includes the same way.
#include "../lib/hiz_walk.glsl"

// Two rays per invocation, walked in lockstep (seed 002 4.7.2's point: more independent
// dependent-fetch chains in flight; on llvmpipe, where an invocation is a SIMD lane, the CPU
// overlaps the two chains' latencies: 1.08-1.15x). A group of 8x4 invocations serves the 64 trace
// pixels (or ray-list entries) an 8x8 group served. A row of 8 invocations (one SIMD vector on
// llvmpipe, which steps it until its longest walk ends) serves neighbours, which walk alike: rows
// 2y and 2y + 1 of the 8x8 pixels, or 16 consecutive list entries (a 4x4 block of classify's
// list). With rows y, y + 4 and entries i, i + 32 the vector's lanes did 0.67 of the steps it
// paid for on hall (0.75 spheres_and_boxes), now 0.72 (0.80): 1.05-1.1x.
layout(local_size_x = 8, local_size_y = 4, local_size_z = 1) in;

void main() {
    g_max_level = min(ssr.hiz_max_level, hiz_levels() - 1);
    g_start_level = clamp(ssr.hiz_start_level, 0, g_max_level);
    g_stop_level = clamp(ssr.hiz_stop_level, 0, g_max_level);
    g_max_steps = ssr.max_steps;
    g_layers = min(ssr.layers, u_layers_used);
    ivec3 id0, id1;
    bool has0 = slot_entry(0, id0), has1 = slot_entry(1, id1);
    GSample g0, g1;
    bool keep0, keep1;
    ReflectionRay ray0 = slot_ray(id0, has0, g0, keep0);
    ReflectionRay ray1 = slot_ray(id1, has1, g1, keep1);
    HizWalk w0 = walk_start(ray0, keep0 && ray0.weight > 0.0);
    HizWalk w1 = walk_start(ray1, keep1 && ray1.weight > 0.0);
    while (w0.walking || w1.walking) {
        walk_step(w0);
        walk_step(w1);
    }
    if (keep0) slot_store(id0, ray0, g0, w0);
    if (keep1) slot_store(id1, ray1, g1, w1);
#if RAY_LIST && defined(EXTRA_RAYS) && EXTRA_RAYS
    // Frame.stats of the variance-guided second trace (extra_rays, extra_depth_fetches): one
    // counter update for both rays. The first trace counts nothing: Frame.stats sums its rays
    // and fetches from rays.sample when asked (the atomic pair, which llvmpipe runs lane by
    // lane, was a visible share of this pass there).
    bool c0 = keep0 && ray0.weight > 0.0, c1 = keep1 && ray1.weight > 0.0;
    ray_list_add(uint(c0) + uint(c1), (c0 ? uint(walk_fetches(w0)) : 0u) + (c1 ? uint(walk_fetches(w1)) : 0u));
#endif
}
