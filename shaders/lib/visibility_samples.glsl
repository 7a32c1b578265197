// Every sample of the deep G-buffer, listed by the selection of
// "visibility_lists" (passes/visibility_select.comp, LIST_SAMPLES: the CPU device, no textured
// material) for the attribute pass's shade stage (passes/gbuffer_attributes.comp), with every
// layer's sample count. The list itself (per sample two uints: lib/visibility.glsl's
// sample_index and the sample's id, so that the shade stage reads no id texture; in no
// particular order) is a buffer of its own, written and read as an RG32UI image buffer. Needs frame_uniforms.
layout(std430, binding = BUFFER_VISIBILITY_SAMPLES) coherent buffer VisibilitySamples {
    // The shade stage's indirect dispatch: x groups of 64 over the list, y and z 1; w the samples
    // listed.
    uvec4 visibility_samples_dispatch;
    uint visibility_layer_samples[16];  // layer k: the pixels holding more than k layers
};
