#version 450 core
// Draws reflection directions with the same GLSL the trace passes use, for a given view
// direction and roughness, and writes each direction with its weight and pdf: the sampling
// code under test (and under study, e.g. the thesis's Figs. 2.5 and 2.6), not a copy of it.
#include "../lib/ssr_settings.glsl"
#include "../lib/brdf.glsl"
#include "../lib/random.glsl"
#include "../lib/ggx_sampling.glsl"

layout(local_size_x = 64) in;

uniform vec3 u_view;  // local frame, n = +z
uniform float u_alpha;
uniform int u_method;
uniform uint u_count;
uniform uint u_seed;
uniform int u_stratified;  // 1: a Hammersley set rotated by one random offset

layout(std430, binding = BUFFER_SAMPLES) writeonly buffer Samples { vec4 samples[]; };  // (l.xyz, weight), (pdf, u, reuse weight) pairs

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_count) return;
    vec2 u = vec2(unit_float(pcg_hash(2u * i ^ pcg_hash(u_seed))), unit_float(pcg_hash((2u * i + 1u) ^ pcg_hash(u_seed))));
    if (u_stratified != 0) {
        vec2 offset = vec2(unit_float(pcg_hash(u_seed)), unit_float(pcg_hash(u_seed + 1u)));
        u = fract(hammersley(i, u_count) + offset);
    }
    vec3 v = normalize(u_view);
    BrdfSample s = sample_reflection(v, u_alpha, u_method, u);
    // The resolve's BRDF reuse weight (brdf.glsl) for this very direction and pdf: for
    // a pixel's own ray it must reproduce the sampler's weight.
    float reuse = s.pdf > 0.0 && s.weight > 0.0
        ? brdf_cosine_over_pdf(vec3(0.0, 0.0, 1.0), v, s.l, u_alpha, brdf_cosine_receiver(v.z, u_alpha), s.pdf)
        : 0.0;
    samples[2u * i] = vec4(s.l, s.weight);
    samples[2u * i + 1u] = vec4(s.pdf, u, reuse);
}
