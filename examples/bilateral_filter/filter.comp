#version 450 core
// An edge-aware spatial filter of the resolved reflection, after the spatial denoiser AMD describes
// for FidelityFX SSSR (Stochastic Screen-Space Reflections, GPUOpen documentation, 2020): glossy
// reflections traced with few rays per pixel are averaged over neighbours that lie on the same
// surface (similar depth and normal) and have a similar roughness, over a radius that grows with
// the roughness, while mirror-like pixels (roughness below `u_min_roughness`) keep their rays' result.
// Written from that description; the weights are the common bilateral ones (Tomasi & Manduchi 1998).
//
// The GLSL contract of a reflection_filter (docs/guide/glsl-contract.md): the declared reads at
// texture units 0, 1, ... in order (`reflection` is a copy taken before the pass runs), the
// rewritten `reflection` at image unit 0, one invocation per pixel in 8x8 groups, parameters
// as uniforms u_<name>.
#include "lib/frame_uniforms.glsl"
#include "lib/gbuffer.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0) uniform sampler2D u_reflection;         // reads[0]: reflection (RGBA16F; a = 1 where reflecting)
layout(binding = 1) uniform sampler2DArray u_linear_depth;  // reads[1]: view depth, layer 0 = nearest surface
layout(binding = 2) uniform sampler2DArray u_normal;        // reads[2]: gbuffer.normal (xyz normal, w roughness)
layout(rgba16f, binding = 0) writeonly uniform image2D o_reflection;

uniform int u_radius;             // largest filter radius in pixels (at roughness 1)
uniform float u_sigma_depth;      // relative depth difference that halves a tap's weight (x ln 2)
uniform float u_normal_power;     // taps weigh max(0, n_p . n_q)^power
uniform float u_min_roughness;    // pixels smoother than this are left as traced

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(frame.viewport.xy);
    if (any(greaterThanEqual(p, size))) return;
    vec4 centre = texelFetch(u_reflection, p, 0);
    vec4 nr = texelFetch(u_normal, ivec3(p, 0), 0);
    float roughness = nr.w;
    // Radius from the roughness: wide lobes are noisy and blurry anyway; mirrors stay sharp.
    int radius = int(round(float(u_radius) * clamp(roughness, 0.0, 1.0)));
    if (centre.a <= 0.0 || roughness < u_min_roughness || radius == 0) {
        imageStore(o_reflection, p, centre);
        return;
    }
    vec3 n = normalize(nr.xyz);
    float z = texelFetch(u_linear_depth, ivec3(p, 0), 0).r;
    vec3 sum = vec3(0.0);
    float wsum = 0.0;
    float sigma_s = max(float(radius) * 0.5, 0.5);
    for (int dy = -radius; dy <= radius; ++dy) {
        for (int dx = -radius; dx <= radius; ++dx) {
            ivec2 q = p + ivec2(dx, dy);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            vec4 c = texelFetch(u_reflection, q, 0);
            if (c.a <= 0.0) continue;
            vec4 nq = texelFetch(u_normal, ivec3(q, 0), 0);
            float zq = texelFetch(u_linear_depth, ivec3(q, 0), 0).r;
            float w = exp(-float(dx * dx + dy * dy) / (2.0 * sigma_s * sigma_s));
            w *= exp(-abs(zq - z) / max(u_sigma_depth * z, 1e-6));
            w *= pow(max(dot(n, normalize(nq.xyz)), 0.0), u_normal_power);
            w *= exp(-abs(nq.w - roughness) * 8.0);  // similar roughness: similar lobes
            sum += w * c.rgb;
            wsum += w;
        }
    }
    imageStore(o_reflection, p, vec4(wsum > 0.0 ? sum / wsum : centre.rgb, centre.a));
}
