#version 450 core
// Integrates the split-sum table (A, B) of lib/specular_albedo.glsl: one invocation per
// (n.v, roughness) cell, a Hammersley set of directions drawn by the tracers' own sampler
// (VNDF: every sample lands on the visible lobe, so the estimate is smooth), GGX alpha =
// roughness^2 as the trace passes use it.
#include "../lib/ssr_settings.glsl"
#include "../lib/brdf.glsl"
#include "../lib/random.glsl"
#include "../lib/ggx_sampling.glsl"
#include "../lib/specular_albedo.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = IMAGE_TABLE, rg32f) writeonly uniform image2D o_table;
uniform uint u_samples;

void main() {
    ivec2 cell = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(cell, ivec2(SPECULAR_ALBEDO_SIZE)))) return;
    // Cell centres sit at the range ends (specular_albedo_uv); n.v = 0 is a limit only.
    vec2 x = vec2(cell) / float(SPECULAR_ALBEDO_SIZE - 1);
    float NoV = max(x.x, 1e-3);
    float alpha = x.y * x.y;
    vec3 v = vec3(sqrt(1.0 - NoV * NoV), 0.0, NoV);
    vec2 ab = vec2(0.0);
    for (uint i = 0u; i < u_samples; ++i) {
        BrdfSample s = sample_reflection(v, alpha, SAMPLING_VNDF, hammersley(i, u_samples));
        if (s.weight <= 0.0) continue;
        float VoH = clamp(dot(v, normalize(v + s.l)), 0.0, 1.0);
        float fc = pow(1.0 - VoH, 5.0);
        ab += s.weight * vec2(1.0 - fc, fc);
    }
    imageStore(o_table, cell, vec4(ab / float(u_samples), 0.0, 0.0));
}
