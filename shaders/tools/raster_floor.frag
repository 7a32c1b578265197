#version 450 core
// The device's floors under the deep G-buffer's constructions (Renderer::raster_floor,
// benchmarks/timing/raster_floor.py): the scene's own triangles through the G-buffer's vertex shader
// (passes/depth_peel.vert), and fragment stages that do nothing but the writes each construction
// cannot avoid, so that a construction's time can be set beside the least its raster work costs.
// One variant per floor (define one):
//   FLOOR_DEPTH        no output: the depth test and depth writes alone (peeling's depth pass,
//                      seed 000 2.2, without its peel test)
//   FLOOR_GBUFFER      constants into the G-buffer's three colour targets (sRGB RGBA8 albedo,
//                      RGBA16F normal, RGBA8 material) with the depth: one layer written through
//                      the raster's colour outputs, as the shading pass of peeling writes it
//   FLOOR_ID           a 32-bit triangle id into an R32UI target with the depth: one layer of
//                      Burns and Hunt 2013's visibility buffer
//   FLOOR_COUNT        counts every fragment of its pixel (the untimed pass that sizes the append)
//   FLOOR_APPEND       appends every fragment's 8 bytes (window depth, triangle id) to its pixel's
//                      array at the pixel's offset (the counts' prefix sum): one store and one
//                      atomic per fragment, the least an exact one-pass construction writes
//   FLOOR_APPEND_LIST  the same 8 bytes into a linked list (Yang et al. 2010): a global slot
//                      counter, the slot's link and the head exchanged, 12 bytes a fragment, the
//                      structure of deep_gbuffer 'visibility_lists' (lib/visibility_lists.glsl)
#include "../lib/frame_uniforms.glsl"

uniform uint u_id_base;  // the draw's bits of the id: its object above the primitive's bits

#if FLOOR_GBUFFER
layout(location = 0) out vec4 o_albedo;
layout(location = 1) out vec4 o_normal;
layout(location = 2) out vec4 o_material;
#elif FLOOR_ID
layout(location = 0) out uint o_id;
#elif FLOOR_COUNT || FLOOR_APPEND
layout(std430, binding = BUFFER_FLOOR_COUNTS) buffer FloorCounts { uint floor_count[]; };
layout(std430, binding = BUFFER_FLOOR_OFFSETS) readonly buffer FloorOffsets { uint floor_offset[]; };
layout(std430, binding = BUFFER_FLOOR_FRAGMENTS) writeonly buffer FloorFragments { uvec2 floor_fragment[]; };
#elif FLOOR_APPEND_LIST
layout(std430, binding = BUFFER_FLOOR_HEADS) coherent buffer FloorHeads { uint floor_head[]; };
layout(std430, binding = BUFFER_FLOOR_LINKS) writeonly buffer FloorLinks { uint floor_next[]; };
layout(std430, binding = BUFFER_FLOOR_FRAGMENTS) writeonly buffer FloorFragments { uvec2 floor_fragment[]; };
layout(std430, binding = BUFFER_FLOOR_COUNTER) coherent buffer FloorCounter { uint floor_slots; };
#endif

void main() {
#if FLOOR_GBUFFER
    o_albedo = vec4(0.5, 0.5, 0.5, 1.0);
    o_normal = vec4(0.0, 0.0, 1.0, 0.0);
    o_material = vec4(0.0, 0.5, 0.5, 1.0);
#elif FLOOR_ID
    o_id = u_id_base | uint(gl_PrimitiveID);
#elif FLOOR_COUNT || FLOOR_APPEND
    uint pixel = uint(gl_FragCoord.y) * uint(frame.viewport.x) + uint(gl_FragCoord.x);
    uint n = atomicAdd(floor_count[pixel], 1u);
#if FLOOR_APPEND
    floor_fragment[floor_offset[pixel] + n] = uvec2(floatBitsToUint(gl_FragCoord.z), u_id_base | uint(gl_PrimitiveID));
#endif
#elif FLOOR_APPEND_LIST
    uint pixel = uint(gl_FragCoord.y) * uint(frame.viewport.x) + uint(gl_FragCoord.x);
    uint slot = atomicAdd(floor_slots, 1u);
    floor_fragment[slot] = uvec2(floatBitsToUint(gl_FragCoord.z), u_id_base | uint(gl_PrimitiveID));
    floor_next[slot] = atomicExchange(floor_head[pixel], slot);
#endif
}
