#version 450 core
// trace_hiz: hierarchical traversal of a min-max depth pyramid (seed 002, 4.4.3 and 4.5.3),
// over every G-buffer layer. The screen-space ray o + v t (t in [0, 1]; x, y in pixels, z in
// screen depth s, all affine in screen space) walks cells: where its segment inside a cell
// misses every layer's slab [min, max + thickness] the whole cell is skipped and the walk
// goes up a level; where it overlaps one, the walk goes down; an overlap at the stop level
// is the hit. The max pyramid lets rays pass behind surfaces (4.6.6) and the slab test
// serves rays toward the camera as well (4.6.7). Origins are snapped to pixel centres and
// cell crossings step a small offset past the boundary (the Stingray finding).
//
// Deep layers: a cell holds one (min, max) per layer; the walk tests layers front to back
// and stops at the first layer whose slab the segment overlaps (-> descend), or at the first
// layer it lies in front of, or an empty one (-> skip the cell). Layers are depth-sorted per
// pixel, so each layer's min over a cell is at least the previous layer's: a ray in front
// of the front layer costs one fetch per cell whatever the layer count; only rays that
// travel behind surfaces pay for deeper layers.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/ssr_settings.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/brdf.glsl"
#include "../lib/random.glsl"
#include "../lib/ggx_sampling.glsl"
#include "../lib/ray_generation.glsl"
#include "../lib/screen_ray.glsl"
#include "../lib/trace_common.glsl"
#if RAY_LIST
#include "../lib/ray_list.glsl"
#endif
#include "../lib/hiz_cells.glsl"
#include "../lib/hiz_atlas.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler2DArray u_linear_depth;
layout(binding = 1) uniform sampler2DArray u_albedo;
layout(binding = 2) uniform sampler2DArray u_normal;
layout(binding = 3) uniform sampler2DArray u_material;
// RG32F (min s, slab back s) per layer, every level in one image (lib/hiz_atlas.glsl): lod 0
layout(binding = 4) uniform sampler2DArray u_hiz_trace;

float g_fetches = 0.0;
// Issue 11: the layers that hold a surface somewhere (frame.stats["layers_used"] with
// Settings.skip, else Settings.layers), set by trace_pass.cpp: the walk never fetches a layer
// empty everywhere, where it would only find the empty layer that ends it.
uniform int u_layers_used;

// GL's mip size rule, max(1, size >> level). Computed rather than asked of textureSize():
// llvmpipe answers textureSize with the lod of one lane when lanes ask for different levels.
ivec2 hiz_level_size(int level) {
    return max(ivec2(frame.viewport.xy) >> level, ivec2(1));
}

// (min s, slab back s) of a cell: lod 0 whatever the level (issue 13, lib/hiz_atlas.glsl).
vec2 hiz_fetch(ivec2 cell, int layer, int level) {
    g_fetches += 1.0;
    return texelFetch(u_hiz_trace, ivec3(hiz_atlas_origin(level) + cell, layer), 0).xy;
}

// The first layer whose slab the ray segment's screen-depth range [lo, hi] overlaps in
// `cell`, -1 for none; `front` receives that layer's nearest screen depth there.
// A layer covering nothing in the cell has min HIZ_EMPTY, so `hi < min` ends the walk there
// too (nor does any deeper layer cover it). The slab's back (behind the max, or infinity for
// a min-only Hi-Z) is the atlas texel's second value. (Testing layer 0 before the loop, as
// straight-line code, measured 1.4x slower on llvmpipe: keep the one loop.)
int cell_overlap(ivec2 cell, int level, float lo, float hi, out float front) {
    front = 0.0;
    int found = -1;
    for (int k = 0; k < min(ssr.layers, u_layers_used); ++k) {
        vec2 mb = hiz_fetch(cell, k, level);
        if (hi < mb.x) break;  // in front of this layer, so of every deeper one
        if (lo <= mb.y) {
            front = mb.x;
            found = k;
            break;
        }
    }
    return found;
}

struct HizHit {
    bool hit;
    vec2 pixel;
    int layer;
    float s;  // screen depth of the surface hit
};

HizHit trace_hiz(ReflectionRay ray) {
    HizHit result;
    result.hit = false;
    float len = ray_length_in_front_of_near(ray.origin, ray.dir, ssr.max_distance);
    vec3 end = ray.origin + ray.dir * len;
    vec3 a = view_to_pixel(ray.origin), b = view_to_pixel(end);
    vec3 o = vec3(a.xy, screen_depth_of_view(-ray.origin.z));
    vec3 e = vec3(b.xy, screen_depth_of_view(-end.z));
    e = mix(o, e, screen_exit(o.xy, e.xy, frame.viewport.xy));
    // Issue 8: an origin pushed off its surface by a large origin_bias can project outside the
    // image, where the pyramid has no cells (texelFetch outside a level is undefined and gave
    // hits off the screen): such a ray is not traced.
    if (any(lessThan(o.xy, vec2(0.0))) || any(greaterThanEqual(o.xy, frame.viewport.xy))) return result;
    o.xy = floor(o.xy) + 0.5;  // snap the origin to its pixel centre: never on a cell edge
    vec3 v = e - o;
    float major = max(abs(v.x), abs(v.y));
    if (major < 0.5) return result;  // the ray stays inside its own pixel on screen
    float eps_t = ssr.hiz_crossing_offset / major;
    int max_level = min(ssr.hiz_max_level, hiz_levels() - 1);
    int start_level = clamp(ssr.hiz_start_level, 0, max_level);
    int stop_level = clamp(ssr.hiz_stop_level, 0, max_level);

    // Leave the origin's pixel first, so the ray does not hit the surface it starts on.
    float t = hiz_cell_exit(o.xy, v.xy, hiz_cell(o.xy, 0), 0) + eps_t;
    int linear_left = ssr.hiz_linear_steps;  // seed 002, 4.7.1: a few level-0 steps first
    int level = linear_left > 0 ? 0 : start_level;

    // The walk leaves its loop by `break` and resolves a hit after it: a `return` inside the
    // loop (here and in cell_overlap) measured 1.1-1.2x slower on llvmpipe (issue 13).
    int layer = -1;
    float t_out = 0.0, sa = 0.0, front = 0.0;
    ivec2 cell = ivec2(0);
    for (int i = 0; i < ssr.max_steps && t < 1.0; ++i) {
        vec2 pos = o.xy + v.xy * t;
        cell = hiz_cell(pos, level);
        t_out = min(hiz_cell_exit(o.xy, v.xy, cell, level), 1.0);
        sa = o.z + v.z * t;
        float sb = o.z + v.z * t_out;
        layer = cell_overlap(cell, level, min(sa, sb), max(sa, sb), front);
        if (layer >= 0 && level <= stop_level) break;
        // Nothing for this ray in the cell: cross it and go up (after the linear steps, the
        // level stays 0 while they last); else go down. Selects, no branches.
        bool miss = layer < 0;
        int up = linear_left > 1 ? level : linear_left == 1 ? start_level : min(level + 1, max_level);
        t = miss ? t_out + eps_t : t;
        level = miss ? up : level - 1;
        linear_left = miss ? max(linear_left - 1, 0) : linear_left;
        layer = -1;
    }
    if (layer >= 0) {
        // Where the ray reaches the surface inside the cell (at once if already behind it).
        float th = (v.z > 0.0 && sa < front) ? (front - o.z) / v.z : t;
        th = clamp(th, t, t_out);
        vec2 lo, hi;
        hiz_cell_bounds(cell, level, lo, hi);
        result.hit = true;
        result.pixel = clamp(o.xy + v.xy * th, lo + 0.001, hi - 0.001);  // off the cell's edges (issue 8)
        result.layer = layer;
        result.s = front;
    }
    return result;
}

void main() {
#if RAY_LIST
    // Only the pixels the classify pass listed (issue 11); it wrote the others' outputs.
    ivec3 id;
    if (!ray_list_entry(id)) return;
#else
    ivec3 id = ivec3(gl_GlobalInvocationID);
    if (id.x >= ssr.trace_width || id.y >= ssr.trace_height) return;
#endif
    ivec2 p = origin_pixel(id.xy);
    GSample g = gbuffer_decode(texelFetch(u_albedo, ivec3(p, 0), 0), texelFetch(u_normal, ivec3(p, 0), 0),
                               texelFetch(u_material, ivec3(p, 0), 0));
#if defined(EXTRA_RAYS) && EXTRA_RAYS
    // Issue 11's variance-guided second pass (variance_rays.comp listed this pixel): only the
    // rays adaptive_rays left out, drawn exactly as a full trace draws ray id.z.
    if (id.z < adaptive_ray_count(g.roughness)) return;
#endif
    vec3 pos = view_position(vec2(p) + 0.5, texelFetch(u_linear_depth, ivec3(p, 0), 0).r);
    ReflectionRay ray = generate_ray(g, pos, id.xy, id.z);
    vec4 hit = vec4(0.0);
    if (ray.weight > 0.0) {
        HizHit h = trace_hiz(ray);
        if (h.hit) {
            vec3 hit_view = view_position(h.pixel, view_depth_of_screen(h.s));
            hit = vec4(h.pixel, float(h.layer + 1), hit_fade(h.pixel, ray.origin, ray.dir, hit_view));
        }
    }
    store_ray(id, ray, is_reflective(g), hit, g_fetches);
#if RAY_LIST
    ray_list_count(ray.weight, g_fetches);
#endif
}
