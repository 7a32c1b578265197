#version 450 core
// visibility_buffer select (deep_gbuffer "visibility_lists"): per pixel, the LAYERS nearest
// distinct depths of its list of visibility samples (lib/visibility_lists.glsl), in depth order,
// exactly as depth peeling finds them (the rules of passes/deep_gbuffer_select.comp): layer 0 is
// the nearest fragment nearer than the depth clear value, layer i+1 the nearest strictly behind
// layer i (with MIN_SEPARATION 1, behind it by the minimum separation: the list is then walked
// once per layer), fragments at equal depth make one layer, and of those the one peeling's
// shading pass leaves stays (visibility_wins).
//   output: gbuffer.visibility (IMAGE_GBUFFER_VISIBILITY) every layer's triangle where the pixel has that
//           layer (elsewhere not written: nothing reads it there); gbuffer.depth (IMAGE_GBUFFER_DEPTH,
//           R32F with this construction) its window depth, the clear value where none (stored
//           here or cleared before, STORE_EMPTY_DEPTH): stored here, not drawn, since a
//           compute store skips the raster outputs a depth target is written through (on an H200
//           a full-screen depth-only draw per 1080p layer cost 0.45 ms, more than the attributes
//           of all 8 layers); visibility_counter.z the most layers any pixel holds; with
//           MARK_TILES (the CPU device) the tiles of each layer holding a sample
//           (lib/visibility_tiles.glsl); with LIST_SAMPLES (the CPU device, no textured
//           material) every kept sample, listed for the attribute pass's shade stage
//           (lib/visibility_samples.glsl), and every layer's sample count: this pass knows each
//           pixel's layers, where the attribute pass would classify every texel of every layer
//           (shading the empty lanes of a vector too, on that device) to find them.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/visibility.glsl"
#include "../lib/visibility_lists.glsl"
#include "../lib/layer_separation.glsl"
#ifndef MARK_TILES
#define MARK_TILES 0
#endif
#if MARK_TILES
#include "../lib/visibility_tiles.glsl"
#endif
// STORE_EMPTY_DEPTH 1 (clears by compute, a GPU): an empty texel's depth is stored here, the clear
// by compute of that layer; 0: the depth array was cleared before (glClearTexSubImage, a memset
// on the CPU device), and only the kept depths are stored.
#ifndef STORE_EMPTY_DEPTH
#define STORE_EMPTY_DEPTH 1
#endif
#ifndef LIST_SAMPLES
#define LIST_SAMPLES 0
#endif
#if LIST_SAMPLES
#include "../lib/visibility_samples.glsl"
layout(binding = IMAGE_VISIBILITY_SAMPLES, rg32ui) writeonly uniform uimageBuffer u_samples;  // the list: (sample, id)
shared uint group_count[64];  // each pixel's layers
shared uint group_first[64];  // each pixel's first slot among the group's samples
shared uint group_base;       // the group's first slot in the list
#endif

#ifndef LAYERS
#define LAYERS 1
#endif

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = IMAGE_GBUFFER_VISIBILITY, r32ui) writeonly uniform uimage2DArray o_visibility;
layout(binding = IMAGE_GBUFFER_DEPTH, r32f) writeonly uniform image2DArray o_depth;

// How the lists are read: with FETCH_BY_IMAGE (the CPU device) through image buffers over the same
// storage (passes/visibility_buffer.cpp), which llvmpipe reads inline, where a storage-buffer read
// at a per-invocation address is a loop over the lanes.
#if FETCH_BY_IMAGE
layout(binding = IMAGE_VISIBILITY_LIST_FRAGMENTS, rg32ui) readonly uniform uimageBuffer u_list_fragments;
layout(binding = IMAGE_VISIBILITY_LIST_LINKS, r32ui) readonly uniform uimageBuffer u_list_links;
layout(binding = IMAGE_VISIBILITY_LIST_HEADS, r32ui) readonly uniform uimageBuffer u_list_heads;
uint list_head(uint pixel) { return imageLoad(u_list_heads, int(pixel)).r; }
uvec2 list_fragment(uint i) { return imageLoad(u_list_fragments, int(i)).xy; }
uint list_next(uint i) { return imageLoad(u_list_links, int(i)).r; }
#else
uint list_head(uint pixel) { return visibility_head[pixel]; }
uvec2 list_fragment(uint i) { return visibility_fragment[i]; }
uint list_next(uint i) { return visibility_next[i]; }
#endif

shared uint group_layers;

// Pixel p's layer k: its id and depth (`kept`: the pixel holds more than k layers). An id is read
// only where a sample is (the attribute pass tests the depth, or shades the listed samples): no
// store for an empty texel.
void store_layer(ivec2 p, int k, bool kept, float depth, uint triangle) {
    if (kept) imageStore(o_visibility, ivec3(p, k), uvec4(triangle));
#if STORE_EMPTY_DEPTH
    imageStore(o_depth, ivec3(p, k), vec4(kept ? depth : DEPTH_CLEAR));
#else
    if (kept) imageStore(o_depth, ivec3(p, k), vec4(depth));
#endif
}

void main() {
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (gl_LocalInvocationIndex == 0u) group_layers = 0u;
    barrier();
    int count = 0;
    bool inside = p.x < size.x && p.y < size.y;
    float depth[LAYERS];
    uint triangle[LAYERS];
    if (inside) {
        uint pixel = uint(p.y * size.x + p.x);
        uint head = list_head(pixel);
#if MIN_SEPARATION
        for (int k = 0; k < LAYERS; ++k) {
            float best = DEPTH_CLEAR;
            uint best_triangle = VISIBILITY_NONE;
            for (uint i = head; i != VISIBILITY_LIST_END; i = list_next(i)) {
                uvec2 f = list_fragment(i);
                float z = uintBitsToFloat(f.x);
                uint t = f.y;
                if (!is_farther(DEPTH_CLEAR, z)) continue;
                if (k > 0 && !behind_layer(z, depth[k - 1])) continue;
                if (best_triangle == VISIBILITY_NONE || is_farther(best, z) ||
                    (z == best && visibility_wins(t, best_triangle))) {
                    best = z;
                    best_triangle = t;
                }
            }
            if (best_triangle == VISIBILITY_NONE) break;
            depth[k] = best;
            triangle[k] = best_triangle;
            count = k + 1;
        }
#else
        // Insertion into the kept layers, sorted nearest first: each slot is compared with
        // constant indices (the loop unrolls), so the layers stay in registers; an index that
        // differs per invocation would keep them in memory, read and written lane by lane on
        // the CPU device. An empty slot holds the clear depth and VISIBILITY_NONE.
        for (int k = 0; k < LAYERS; ++k) {
            depth[k] = DEPTH_CLEAR;
            triangle[k] = VISIBILITY_NONE;
        }
        for (uint i = head; i != VISIBILITY_LIST_END; i = list_next(i)) {
            uvec2 f = list_fragment(i);
            float z = uintBitsToFloat(f.x);
            uint t = f.y;
            if (!is_farther(DEPTH_CLEAR, z)) continue;  // fails the depth test against the clear value
            for (int k = 0; k < LAYERS; ++k) {
                // (z, t) is the nearest sample not yet placed, and the slots before k are nearer.
                // An empty slot holds the clear depth, behind every fragment; a sample merged
                // into a slot at its depth goes on as an empty one (the clear depth and
                // VISIBILITY_NONE), which changes nothing further. Selects, not branches: the CPU
                // device runs both sides of a branch anyway.
                float dk = depth[k];
                uint tk = triangle[k];
                bool same = dk == z;
                bool before = is_farther(dk, z);
                triangle[k] = before || (same && visibility_wins(t, tk)) ? t : tk;
                depth[k] = before ? z : dk;
                t = before ? tk : (same ? VISIBILITY_NONE : t);
                z = before ? dk : (same ? DEPTH_CLEAR : z);
            }
        }
        for (int k = 0; k < LAYERS; ++k) count += triangle[k] != VISIBILITY_NONE ? 1 : 0;  // filled slots come first
#endif
#if !LIST_SAMPLES
        for (int k = 0; k < LAYERS; ++k) store_layer(p, k, k < count, depth[k], triangle[k]);
        if (count > 0) atomicMax(group_layers, uint(count));
#endif
    }
#if LIST_SAMPLES
    group_count[gl_LocalInvocationIndex] = uint(count);
#endif
    barrier();
#if LIST_SAMPLES
    // One invocation places the group's samples (each pixel's first slot: the layers of the pixels
    // before it), counts each layer's (the pixels holding more than k layers) and the most layers
    // a pixel holds: a serial pass over 64 pixels costs less than the atomics a pixel it replaces,
    // which llvmpipe runs lane by lane.
    uint samples = 0u;
    uint holding[LAYERS];
    if (gl_LocalInvocationIndex == 0u) {
        uint most = 0u;
        for (int k = 0; k < LAYERS; ++k) holding[k] = 0u;
        for (uint i = 0u; i < 64u; ++i) {
            uint c = group_count[i];
            group_first[i] = samples;
            samples += c;
            most = max(most, c);
            for (int k = 0; k < LAYERS; ++k) holding[k] += c > uint(k) ? 1u : 0u;
        }
        group_layers = most;
    }
#endif
    if (gl_LocalInvocationIndex == 0u && group_layers > 0u) {
        atomicMax(visibility_counter.z, group_layers);
#if MARK_TILES
        // Layer k of this 8x8 tile holds a sample where some pixel holds more than k layers.
        for (int k = 0; k < int(group_layers); ++k) mark_visibility_tile(ivec2(gl_WorkGroupID.xy) * 8, k);
#endif
#if LIST_SAMPLES
        for (int k = 0; k < LAYERS; ++k)
            if (holding[k] > 0u) atomicAdd(visibility_layer_samples[k], holding[k]);
        group_base = atomicAdd(visibility_samples_dispatch.w, samples);
        atomicMax(visibility_samples_dispatch.x, (group_base + samples + 63u) / 64u);
#endif
    }
#if LIST_SAMPLES
    barrier();
    // The layers are stored here, with their list entries, once the group's slots are placed.
    // The loop runs to the group's most layers (the same bound for every invocation, so it ends
    // for all at once, where a loop to LAYERS would run the masked stores of layers no pixel of
    // the group has); layer k's values are picked by selects at constant indices, which keep the
    // layers in registers.
    uint first = group_base + group_first[gl_LocalInvocationIndex];
    // (Every layer where empty texels take their clear depth here.)
    int most = STORE_EMPTY_DEPTH != 0 ? LAYERS : int(group_layers);
    for (int k = 0; k < most; ++k) {
        float dk = depth[0];
        uint tk = triangle[0];
        for (int j = 1; j < LAYERS; ++j) {
            dk = k == j ? depth[j] : dk;
            tk = k == j ? triangle[j] : tk;
        }
        if (inside) store_layer(p, k, k < count, dk, tk);
        if (k < count) imageStore(u_samples, int(first + uint(k)), uvec4(sample_index(p, k), tk, 0u, 0u));
    }
#endif
}
