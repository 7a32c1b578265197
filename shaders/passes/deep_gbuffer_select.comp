#version 450 core
// deep_gbuffer select: per pixel, the LAYERS nearest distinct depths of its fragment list
// (lib/fragment_lists.glsl), in depth order, exactly as depth peeling finds them
// (passes/depth_peel.cpp): layer 0 is the nearest fragment nearer than the depth clear value
// (the depth test against the cleared buffer), layer i+1 the nearest strictly behind layer i
// (Everitt 2001), so fragments at equal depth make one layer. Of several fragments at a kept
// depth, the one peeling's shading pass writes last stays: it draws the draws in reverse order
// and each draw's triangles in order, so the lowest draw index wins, and within it the highest
// primitive. With MIN_SEPARATION 1 (Settings.min_separation > 0) layer i+1 is instead the nearest
// depth behind layer i by the minimum separation (lib/layer_separation.glsl, the test peeling's
// depth pass applies): it depends on layer i itself, so the list is walked once per layer, as
// peeling draws once per layer.
//   output: kept[layer * width * height + pixel] = the kept fragment's slot, or FRAGMENT_NONE;
//           fragment_counter.z = the most layers any pixel holds; layer_pixels[k] = the pixels
//           layer k covers (Frame.layer_samples); the covered tiles of every layer and layer 0's
//           reflective regions (lib/covered_tiles.glsl), as peeling's shading pass marks them:
//           one group is one 8x8 covered tile, so one invocation marks it, and the write pass
//           stores nothing but its outputs.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/fragment_lists.glsl"
#include "../lib/covered_tiles.glsl"
#include "../lib/layer_separation.glsl"

#ifndef LAYERS
#define LAYERS 1
#endif

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(std430, binding = BUFFER_KEPT_FRAGMENTS) writeonly buffer KeptFragments { uint kept[]; };

shared uint group_reflective;  // 1: a pixel's layer 0 is reflective
shared uint group_count[LAYERS];  // [c - 1]: the tile's pixels holding exactly c layers

// True when fragment a replaces fragment b at the same depth (see above).
bool wins(uint draw_a, uint prim_a, uint draw_b, uint prim_b) {
    return draw_a < draw_b || (draw_a == draw_b && prim_a > prim_b);
}

void main() {
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    uint lane = gl_LocalInvocationIndex;
    if (lane == 0u) group_reflective = 0u;
    if (lane < uint(LAYERS)) group_count[lane] = 0u;
    barrier();

    int count = 0;
    if (p.x < size.x && p.y < size.y) {
        uint pixel = uint(p.y * size.x + p.x);
        float depth[LAYERS];
        uint slot[LAYERS], draw[LAYERS], prim[LAYERS];
        uint head = fragment_head[pixel];
#if MIN_SEPARATION
        for (int k = 0; k < LAYERS; ++k) {
            // The nearest depth behind layer k-1 (layer 0: nearer than the clear value), and of
            // the fragments at it the one peeling's shading pass writes last.
            float best = DEPTH_CLEAR;
            uint best_slot = FRAGMENT_NONE, best_draw = 0u, best_prim = 0u;
            for (uint i = head; i != FRAGMENT_NONE; i = fragments[i].next) {
                float z = fragments[i].depth;
                if (!is_farther(DEPTH_CLEAR, z)) continue;
                if (k > 0 && !behind_layer(z, depth[k - 1])) continue;
                uint d = fragments[i].draw_flags & 0x7fffffffu;
                uint pr = fragments[i].primitive;
                if (best_slot == FRAGMENT_NONE || is_farther(best, z) ||
                    (z == best && wins(d, pr, best_draw, best_prim))) {
                    best = z;
                    best_slot = i;
                    best_draw = d;
                    best_prim = pr;
                }
            }
            if (best_slot == FRAGMENT_NONE) break;
            depth[k] = best;
            slot[k] = best_slot;
            count = k + 1;
        }
#else
        uint i = head;
        while (i != FRAGMENT_NONE) {
            float z = fragments[i].depth;
            uint d = fragments[i].draw_flags & 0x7fffffffu;
            uint pr = fragments[i].primitive;
            uint here = i;
            i = fragments[i].next;
            if (!is_farther(DEPTH_CLEAR, z)) continue;  // fails the depth test against the clear value
            // The first kept depth not nearer than z.
            int j = 0;
            while (j < count && is_farther(z, depth[j])) ++j;
            if (j < count && depth[j] == z) {
                if (wins(d, pr, draw[j], prim[j])) {
                    slot[j] = here;
                    draw[j] = d;
                    prim[j] = pr;
                }
                continue;
            }
            if (j >= LAYERS) continue;
            for (int k = min(count, LAYERS - 1); k > j; --k) {
                depth[k] = depth[k - 1];
                slot[k] = slot[k - 1];
                draw[k] = draw[k - 1];
                prim[k] = prim[k - 1];
            }
            depth[j] = z;
            slot[j] = here;
            draw[j] = d;
            prim[j] = pr;
            count = min(count + 1, LAYERS);
        }
#endif
        uint plane = uint(size.x * size.y);
        for (int k = 0; k < LAYERS; ++k) kept[uint(k) * plane + pixel] = k < count ? slot[k] : FRAGMENT_NONE;
        if (count > 0) {
            atomicAdd(group_count[count - 1], 1u);
            if ((fragments[slot[0]].draw_flags & 0x80000000u) != 0u) group_reflective = 1u;
        }
    }
    barrier();
    // Layer k covers the pixels holding more than k layers.
    if (lane < uint(LAYERS)) {
        uint covering = 0u;
        for (int c = int(lane); c < LAYERS; ++c) covering += group_count[c];
        if (covering > 0u) atomicAdd(layer_pixels[lane], covering);
    }
    if (lane != 0u) return;
    uint group_layers = 0u;
    for (int c = LAYERS; c > 0 && group_layers == 0u; --c)
        if (group_count[c - 1] > 0u) group_layers = uint(c);
    if (group_layers == 0u) return;
    atomicMax(fragment_counter.z, group_layers);
    ivec2 grid = covered_tile_grid();
    ivec2 tile = ivec2(gl_WorkGroupID.xy);
    for (int k = 0; k < int(group_layers); ++k) covered_tile[(k * grid.y + tile.y) * grid.x + tile.x] = 1u;
    if (group_reflective != 0u) {
        // Its 32x32 region holds a reflective surface: the first tile to flag it lists it.
        uint base = classify_regions_base(int(frame.clip.z));
        ivec2 regions = classify_region_grid();
        ivec2 region = tile * COVERED_TILE_SIZE / CLASSIFY_REGION_SIZE;
        uint r = uint(region.y * regions.x + region.x);
        if (atomicExchange(covered_tile[base + 4u + r], 1u) == 0u) {
            uint n = atomicAdd(covered_tile[base], 1u);
            covered_tile[base + 4u + uint(regions.x * regions.y) + n] = r;
        }
    }
}
