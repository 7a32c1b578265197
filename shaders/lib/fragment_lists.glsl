// Per-pixel fragment lists of the one-pass deep G-buffer (Yang, Hensley, Grün and Thibieroz
// 2010, "Real-time concurrent linked list construction on the GPU"): every fragment of the
// geometry pass takes a slot of the fragment store from an atomic counter and links itself
// in front of its pixel's list with an atomic exchange on the pixel's head. The store holds
// what the G-buffer writes (the encoded outputs, before the framebuffer's format conversion),
// so the write pass converts the kept fragments exactly as the peeling's shading pass does.
// A slot beyond the store's capacity is counted but not written: the renderer reads the
// counter and redoes the pass with a store that fits, or peels (passes/depth_peel.cpp), so a
// list is never silently truncated.
#define FRAGMENT_NONE 0xffffffffu
// EMISSION_TEXTURE 1 (a scene with an emissive texture): every fragment carries the G-buffer's 4th
// output, gbuffer.emission, too (80 bytes a fragment instead of 64: DepthPeelPass::fragment_bytes).
#ifndef EMISSION_TEXTURE
#define EMISSION_TEXTURE 0
#endif
// SPECULAR_TEXTURE 1 (a scene with a KHR_materials_specular texture): every fragment carries
// gbuffer.specular too (16 bytes more).
#ifndef SPECULAR_TEXTURE
#define SPECULAR_TEXTURE 0
#endif
// MOTION_VECTORS 1 (Settings.motion_vectors): gbuffer.motion too (16 bytes more).
#ifndef MOTION_VECTORS
#define MOTION_VECTORS 0
#endif

struct ListFragment {
    vec4 albedo_metallic;
    vec4 normal_roughness;
    vec4 material;
    float depth;        // window depth, gl_FragCoord.z as the depth test sees it
    uint next;          // the next fragment of the pixel's list, FRAGMENT_NONE at its end
    uint draw_flags;    // bits 0..30: the draw's index; bit 31: reflectivity > 0 (layer 0's regions)
    uint primitive;     // gl_PrimitiveID within the draw
#if EMISSION_TEXTURE
    vec4 emission;
#endif
#if SPECULAR_TEXTURE
    vec4 specular;
#endif
#if MOTION_VECTORS
    vec4 motion;
#endif
};

layout(std430, binding = BUFFER_FRAGMENT_STORE) buffer FragmentStore { ListFragment fragments[]; };
// x: fragments appended (may exceed the capacity), y: the capacity, z: the most layers any pixel
// holds (the selection pass's maximum), w: unused; then the pixels each layer covers.
layout(std430, binding = BUFFER_FRAGMENT_COUNTER) coherent buffer FragmentCounter {
    uvec4 fragment_counter;
    uint layer_pixels[];
};
layout(std430, binding = BUFFER_FRAGMENT_HEADS) coherent buffer FragmentHeads { uint fragment_head[]; };

// emission, specular, motion: stored only with EMISSION_TEXTURE, SPECULAR_TEXTURE, MOTION_VECTORS.
void fragment_list_append(ivec2 pixel, float depth, vec4 albedo_metallic, vec4 normal_roughness, vec4 material,
                          vec4 emission, vec4 specular, vec4 motion, uint draw, uint primitive, bool reflective) {
    uint slot = atomicAdd(fragment_counter.x, 1u);
    if (slot >= fragment_counter.y) return;
    ListFragment f;
    f.albedo_metallic = albedo_metallic;
    f.normal_roughness = normal_roughness;
    f.material = material;
    f.depth = depth;
    f.draw_flags = draw | (reflective ? 0x80000000u : 0u);
    f.primitive = primitive;
#if EMISSION_TEXTURE
    f.emission = emission;
#endif
#if SPECULAR_TEXTURE
    f.specular = specular;
#endif
#if MOTION_VECTORS
    f.motion = motion;
#endif
    f.next = atomicExchange(fragment_head[pixel.y * int(frame.viewport.x) + pixel.x], slot);
    fragments[slot] = f;
}
