#version 450 core
// A user trace pass that is trace_hiz's own main(): the walk comes from ssrlab's shader library
// (lib/hiz_walk.glsl), so its rays must equal method 'hiz''s bit for bit (tests/test_user_passes.py).
#include "lib/hiz_walk.glsl"

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
}
