// The Hi-Z walk of trace_hiz (passes/trace_hiz.comp), includable: a trace pass (the built-in one,
// or a user pass, docs/guide/glsl-contract.md) includes this file and writes a main() that
// finds its slots (slot_entry), draws their rays (slot_ray), walks them (walk_start, walk_step)
// and stores the results (slot_store). The file declares the trace inputs at the units
// trace_pass.cpp binds them to.
//
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
#ifndef HIZ_WALK_GLSL
#define HIZ_WALK_GLSL
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
#include "../lib/input_fetch.glsl"


// By name (trace_pass.cpp, trace_hiz.h); with FETCH_BY_IMAGE the float inputs are images.
INPUT_ARRAY(u_linear_depth, TEXTURE_LINEAR_DEPTH, IMAGE_LINEAR_DEPTH, r32f);
layout(binding = TEXTURE_GBUFFER_ALBEDO) uniform sampler2DArray u_albedo;
INPUT_ARRAY(u_normal, TEXTURE_GBUFFER_NORMAL, IMAGE_GBUFFER_NORMAL, rgba16f);
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;
// RG32F (min s, slab back s) per layer, every level in one image (lib/hiz_atlas.glsl): lod 0
INPUT_ARRAY(u_hiz_trace, TEXTURE_HIZ_TRACE, IMAGE_HIZ_TRACE, rg32f);

// The layers that hold a surface somewhere (frame.stats["layers_used"] with
// Settings.skip, else Settings.layers), set by trace_pass.cpp: the walk never fetches a layer
// empty everywhere, where it would only find the empty layer that ends it.
uniform int u_layers_used;
// Settings the walk reads on every step, read once at the start of main: llvmpipe
// (Mesa 22.3) reads a uniform-block value inside a loop lane by lane, with a bounds check per
// lane, since the loop's mask may have turned lane 0 off (0.91-0.94x of the pass without).
int g_max_level, g_start_level, g_stop_level, g_max_steps, g_layers;
// 1 when exactly one layer is in use (trace_pass.cpp): the layer walk is a single test.
#ifndef TRACE_ONE_LAYER
#define TRACE_ONE_LAYER 0
#endif
// 1 when Settings.hiz_linear_steps > 0 (trace_pass.cpp): the level-0 steps' bookkeeping is
// compiled in only then (each select it costs runs on every step: 1.04x).
#ifndef HIZ_LINEAR_STEPS
#define HIZ_LINEAR_STEPS 1
#endif
// 1 when an exact fallback takes the rays screen space cannot vouch for (trace_pass.cpp): the
// walk ends as a miss where the ray leaves the G-buffer's sight (lib/screen_sight.glsl): behind
// every slab of a cell at any level; at level 0 also where, in front of the pixel's sample, it
// reaches into the slabs of the sight map there: an edge between or beside samples (one more
// fetch per level-0 step). The pyramid's min is then the sight map's (passes/hiz_build.comp,
// HIZ_SIGHT), so a coarse cell the walk skips holds no such edge either, nor one at its border:
// the walk loses a ray wherever a walk over every pixel would. The ray leaves from the exact surface point (no
// origin_bias), the ray the fallback retraces and the confidence test checks. With deep layers
// a coarse cell whose layers the segment lies between is descended into, not skipped: only a
// pixel's own layers say whether the gap is inside an object.
#ifndef STOP_UNSEEN
#define STOP_UNSEEN 0
#endif

// GL's mip size rule, max(1, size >> level). Computed rather than asked of textureSize():
// llvmpipe answers textureSize with the lod of one lane when lanes ask for different levels.
ivec2 hiz_level_size(int level) {
    return max(ivec2(frame.viewport.xy) >> level, ivec2(1));
}

// (min s, slab back s) of a cell: lod 0 whatever the level (lib/hiz_atlas.glsl).
vec2 hiz_fetch(ivec2 cell, int layer, int level) {
    return FETCH(u_hiz_trace, ivec3(hiz_atlas_origin(level) + cell, layer)).xy;
}

// The first layer whose slab the ray segment's screen-depth range [lo, hi] overlaps in
// `cell`, -1 for none; `front` receives that layer's nearest screen depth there.
// A layer covering nothing in the cell has min HIZ_EMPTY, so `hi < min` ends the walk there
// too (nor does any deeper layer cover it). The slab's back (behind the max, or infinity for
// a min-only Hi-Z) is the atlas texel's second value. (Layer 0 tested before a loop over the
// deeper layers that `return`s measured 1.4x slower on llvmpipe than the one loop; without any
// loop, for one layer, 1.3x faster.)
// `stop`: the layer the walk over layers stopped at (the one overlapped, or the first the
// segment lies in front of; g_layers when it lies behind every one), for lib/screen_sight.glsl's
// tests.
int cell_overlap(ivec2 cell, int level, float lo, float hi, out float front, inout float fetches, out int stop) {
#if TRACE_ONE_LAYER
    // One layer in use (the common case; trace_pass.cpp compiles this variant for it): the
    // test without a loop around it, 1.3x faster on llvmpipe than a loop of one iteration.
    vec2 mb = hiz_fetch(cell, 0, level);  // one fetch per step: the walk counts its steps
    front = mb.x;
    bool behind = lo > mb.y && !(hi < mb.x);
    stop = behind ? 1 : 0;
    return hi < mb.x || lo > mb.y ? -1 : 0;
#else
    front = 0.0;
    int found = -1;
    stop = g_layers;
    for (int k = 0; k < g_layers; ++k) {
        vec2 mb = hiz_fetch(cell, k, level);
        fetches += 1.0;
        stop = k;
        if (hi < mb.x) break;  // in front of this layer, so of every deeper one
        if (lo <= mb.y) {
            front = mb.x;
            found = k;
            break;
        }
        stop = g_layers;
    }
    return found;
#endif
}

// A ray's walk: its screen segment o + v t and where the traversal stands: (t, level), from
// which the cell, its exit and the ray's depth there follow (walk_cell). Only what a step
// changes is carried: on llvmpipe every variable the loop writes costs a masked blend per step.
struct HizWalk {
    vec3 o, v;
    vec2 inv_v;   // 1 / v.xy (1e30 along an axis the ray does not move on)
    ivec2 ahead;  // 1 where the ray moves toward +x / +y (or not at all): the cell edge it leaves by
    float eps_t, t, front, fetches;
    int level, linear_left, layer, steps;
    bool walking;  // still walking
    bool valid;   // the segment was set up (a hit can be resolved)
#if STOP_UNSEEN
    bool lost;    // the ray left the G-buffer's sight
#endif
};

HizWalk walk_start(ReflectionRay ray, bool traced) {
    HizWalk w;
    w.fetches = 0.0; w.walking = false; w.valid = false; w.layer = -1; w.steps = 0;
    w.t = 0.0; w.front = 0.0; w.level = 0; w.linear_left = 0;
    w.o = vec3(0.0); w.v = vec3(0.0); w.eps_t = 0.0; w.inv_v = vec2(0.0); w.ahead = ivec2(0);
#if STOP_UNSEEN
    w.lost = false;
#endif
    if (!traced) return w;
    float len = ray_length_in_front_of_near(ray.origin, ray.dir, ssr.max_distance);
    vec3 end = ray.origin + ray.dir * len;
    vec3 a = view_to_pixel(ray.origin), b = view_to_pixel(end);
    vec3 o = vec3(a.xy, screen_depth_of_view(-ray.origin.z));
    vec3 e = vec3(b.xy, screen_depth_of_view(-end.z));
    e = mix(o, e, screen_exit(o.xy, e.xy, frame.viewport.xy));
    // An origin pushed off its surface by a large origin_bias can project outside the
    // image, where the pyramid has no cells (texelFetch outside a level is undefined and gave
    // hits off the screen): such a ray is not traced.
    if (any(lessThan(o.xy, vec2(0.0))) || any(greaterThanEqual(o.xy, frame.viewport.xy))) return w;
    o.xy = floor(o.xy) + 0.5;  // snap the origin to its pixel centre: never on a cell edge
    vec3 v = e - o;
    float major = max(abs(v.x), abs(v.y));
    if (major < 0.5) return w;  // the ray stays inside its own pixel on screen
    w.o = o;
    w.v = v;
    // Along an axis the ray does not move on, the far edge of its cell lies ahead of the
    // origin (a pixel centre), and a huge reciprocal puts that crossing beyond t = 1.
    w.inv_v = mix(1.0 / v.xy, vec2(1e30), equal(v.xy, vec2(0.0)));
    w.ahead = ivec2(greaterThanEqual(v.xy, vec2(0.0)));
    w.eps_t = ssr.hiz_crossing_offset / major;
    // Leave the origin's pixel first, so the ray does not hit the surface it starts on.
    w.t = hiz_cell_exit(o.xy, v.xy, hiz_cell(o.xy, 0), 0) + w.eps_t;
    w.linear_left = ssr.hiz_linear_steps;  // seed 002, 4.7.1: a few level-0 steps first
    w.level = w.linear_left > 0 ? 0 : g_start_level;
    w.valid = true;
    w.walking = ssr.max_steps > 0 && w.t < 1.0;
    return w;
}

// The cell the walk stands in, where the ray leaves it and the ray's screen depth on entering:
// a function of (t, level) alone, recomputed after the loop for the hit. Crossings multiply by
// 1 / v rather than divide (hiz_cell_exit, lib/hiz_cells.glsl, serves the origin's pixel).
void walk_cell(HizWalk w, out ivec2 cell, out float t_out, out float sa) {
    vec2 pos = w.o.xy + w.v.xy * w.t;
    ivec2 size = hiz_level_size(w.level);
    cell = min(ivec2(floor(pos)) >> w.level, size - 1);
    // The edge the ray leaves the cell by, in level-0 pixels: the cell's far side along each
    // axis it moves on (the last cell of a row reaches the image edge, lib/hiz_cells.glsl).
    ivec2 edge = (cell + w.ahead) << w.level;
    edge = mix(edge, ivec2(frame.viewport.xy), equal(cell + w.ahead, size));
    vec2 t_edge = (vec2(edge) - w.o.xy) * w.inv_v;
    t_out = min(min(t_edge.x, t_edge.y), 1.0);
    sa = w.o.z + w.v.z * w.t;
}

#if STOP_UNSEEN
// The sight map (lib/hiz_atlas.glsl: hiz_sight_origin) of a level-0 pixel's layer.
vec2 hiz_sight(ivec2 pixel, int layer) {
    return FETCH(u_hiz_trace, ivec3(hiz_sight_origin() + pixel, layer)).xy;
}

// lib/screen_sight.glsl's tests for one step over `cell` (segment depths [lo, hi], screen depth
// s): behind every slab at any level; at level 0, in the gap behind a layer that faces the
// camera, and, in front of the layer `stop`'s sample, inside the slabs the sight map holds there
// (rule 2). A coarse cell the walk skips lies in front of the sight map over all its pixels.
void walk_sight(inout HizWalk w, ivec2 cell, float lo, float hi, int stop, int layer) {
    bool inside = false;
#if !TRACE_ONE_LAYER
    if (w.level == 0 && layer < 0 && stop > 0 && stop < g_layers) {
        // in the gap behind layer stop - 1: inside its object where it faces the camera
        float s = hiz_fetch(cell, stop - 1, 0).x;
        inside = dot(FETCH(u_normal, ivec3(cell, stop - 1)).xyz, -view_position(vec2(cell) + 0.5, view_depth_of_screen(s))) > 0.0;
    }
#endif
    w.lost = w.lost || (layer < 0 && (stop == g_layers || inside));
    if (w.level > 0) return;
    vec2 edge = hiz_sight(cell, min(stop, g_layers - 1));
    w.fetches += 1.0;
    w.lost = w.lost || (layer < 0 && stop < g_layers && hi >= edge.x && lo <= edge.y);
}
#endif

// One traversal step of an active walk. The walk ends on a hit (layer >= 0) and resolves it
// after the loop (a `return` inside the loop measured 1.1-1.2x slower on llvmpipe).
void walk_step(inout HizWalk w) {
    if (!w.walking) return;
    ivec2 cell;
    float t_out, sa;
    walk_cell(w, cell, t_out, sa);
    float sb = w.o.z + w.v.z * t_out;
    int stop;
    int layer = cell_overlap(cell, w.level, min(sa, sb), max(sa, sb), w.front, w.fetches, stop);
    bool hit = layer >= 0 && w.level <= g_stop_level;
    // Nothing for this ray in the cell: cross it and go up (after the linear steps, the level
    // stays 0 while they last); else go down. Selects, no branches: llvmpipe runs every
    // if-block, taken or not, even on a uniform condition.
    bool miss = layer < 0;
#if STOP_UNSEEN
    walk_sight(w, cell, min(sa, sb), max(sa, sb), stop, layer);
    // between two layers of a coarse cell: down to the pixels, whose layers say if it is inside
    miss = miss && !(w.level > 0 && stop > 0 && stop < g_layers);
    hit = hit && !w.lost;
#endif
#if HIZ_LINEAR_STEPS
    int up = w.linear_left > 1 ? w.level : w.linear_left == 1 ? g_start_level : min(w.level + 1, g_max_level);
    w.linear_left = miss ? max(w.linear_left - 1, 0) : w.linear_left;
#else
    int up = min(w.level + 1, g_max_level);
#endif
    w.layer = hit ? layer : -1;
    w.t = miss ? t_out + w.eps_t : w.t;
    w.level = hit ? w.level : miss ? up : w.level - 1;
    w.steps += 1;
    w.walking = !hit && w.steps < g_max_steps && w.t < 1.0;
#if STOP_UNSEEN
    w.walking = w.walking && !w.lost;
#endif
}

// Depth fetches the walk spent: one per step with one layer (not counted in the loop).
float walk_fetches(HizWalk w) {
#if TRACE_ONE_LAYER
    return float(w.steps);
#else
    return w.fetches;
#endif
}

struct HizHit {
    bool hit;
    vec2 pixel;
    int layer;
    float s;  // screen depth of the surface hit
};

HizHit walk_result(HizWalk w) {
    HizHit result;
    result.hit = false;
#if STOP_UNSEEN
    if (w.lost) return result;
#endif
    if (w.valid && w.layer >= 0) {
        ivec2 cell;
        float t_out, sa;
        walk_cell(w, cell, t_out, sa);
        // Where the ray reaches the surface inside the cell (at once if already behind it).
        float th = (w.v.z > 0.0 && sa < w.front) ? (w.front - w.o.z) / w.v.z : w.t;
        th = clamp(th, w.t, t_out);
        vec2 lo, hi;
        hiz_cell_bounds(cell, w.level, lo, hi);
        result.hit = true;
        result.pixel = clamp(w.o.xy + w.v.xy * th, lo + 0.001, hi - 0.001);  // off the cell's edges
        result.layer = w.layer;
        result.s = w.front;
    }
    return result;
}

// The trace pixel (and ray) of one of this invocation's two slots; false when it has none.
bool slot_entry(int slot, out ivec3 id) {
#if RAY_LIST
    return ray_list_entry_at((gl_WorkGroupID.y * RAY_LIST_ROW + gl_WorkGroupID.x) * 64u +
                             gl_LocalInvocationID.y * 16u + uint(slot) * 8u + gl_LocalInvocationID.x, id);
#else
    id = ivec3(gl_WorkGroupID.xy * uvec2(8u, 8u) + uvec2(gl_LocalInvocationID.x, gl_LocalInvocationID.y * 2u + uint(slot)),
               gl_WorkGroupID.z);
    return id.x < ssr.trace_width && id.y < ssr.trace_height;
#endif
}

// The ray of a slot; `keep` false where the slot writes nothing (no entry, or, in the
// variance-guided second pass, a ray the first pass traced).
ReflectionRay slot_ray(ivec3 id, bool has, out GSample g, out bool keep) {
    ivec2 p = origin_pixel(has ? id.xy : ivec2(0));
    g = gbuffer_decode(texelFetch(u_albedo, ivec3(p, 0), 0), FETCH(u_normal, ivec3(p, 0)),
                       texelFetch(u_material, ivec3(p, 0), 0));
    keep = has;
#if defined(EXTRA_RAYS) && EXTRA_RAYS
    // The variance-guided second pass (variance_rays.comp listed this pixel): only the
    // rays adaptive_rays left out, drawn exactly as a full trace draws ray id.z.
    if (id.z < adaptive_ray_count(g.roughness)) keep = false;
#endif
    vec3 pos = view_position(vec2(p) + 0.5, FETCH(u_linear_depth, ivec3(p, 0)).r);
    ReflectionRay ray = generate_ray(g, pos, id.xy, id.z);
#if STOP_UNSEEN
    // From the exact surface point, as the fallback retraces the ray and the confidence test
    // checks its hit (passes/trace_bvh.comp): lifted by origin_bias, a ray passed beside the edge
    // of a box or sphere that the true ray meets, and the hit it found on the wall behind is where
    // the true ray crosses the wall too, which no test of the hit can tell from a true one.
    ray.origin = pos;
#endif
    return ray;
}

void slot_store(ivec3 id, ReflectionRay ray, GSample g, HizWalk w) {
    HizHit h = walk_result(w);
    vec4 hit = vec4(0.0);
#if STOP_UNSEEN
    // A ray lost from sight: a miss marked as the confidence test marks the hits it rejects,
    // for the fallback to retrace.
    if (w.lost) hit = vec4(0.0, 0.0, 0.0, -1.0);
#endif
    if (h.hit) {
        vec3 hit_view = view_position(h.pixel, view_depth_of_screen(h.s));
        hit = vec4(h.pixel, float(h.layer + 1), hit_fade(h.pixel, ray.origin, ray.dir, hit_view));
    }
    store_ray(id, ray, is_reflective(g), hit, walk_fetches(w));
}
#endif
