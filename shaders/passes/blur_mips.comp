#version 450 core
// blur_mips (seed 004 "Glossy" and "Mipmap Generation"): the engines' glossy
// baseline. One mirror ray per pixel; where it hits, the reflection is the pre-convolved
// colour of the hit layer at the hit, read trilinearly at the mip level whose blur matches
// the cone's footprint there: the cone of lib/cone_angle.glsl (half of the GGX lobe) has
// radius tan(theta) * d at the hit, d the ray's length on screen in pixels, and level
// log2 of that radius (+ Settings.cone_level_bias). No visibility, no occlusion along the
// cone: the blur mixes whatever lies around the hit on screen. Misses and faded hits take
// the environment averaged over the GGX lobe (lib/glossy_common.glsl); a footprint under half
// a pixel reads the lit layer exactly, and a mirror the environment at the mirror direction,
// as the resolve does.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/ssr_settings.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/environment.glsl"
#include "../lib/brdf.glsl"
#include "../lib/random.glsl"
#include "../lib/ggx_sampling.glsl"
#include "../lib/screen_ray.glsl"
#include "../lib/cone_angle.glsl"
#include "../lib/glossy_common.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = TEXTURE_RAYS_HIT) uniform sampler2DArray u_hit;
layout(binding = TEXTURE_RAYS_SAMPLE) uniform sampler2DArray u_sample;
layout(binding = TEXTURE_RAYS_DIRECTION) uniform sampler2DArray u_direction;
layout(binding = TEXTURE_LIT) uniform sampler2DArray u_lit;
layout(binding = TEXTURE_LINEAR_DEPTH) uniform sampler2DArray u_linear_depth;
layout(binding = TEXTURE_GBUFFER_ALBEDO) uniform sampler2DArray u_albedo;
layout(binding = TEXTURE_GBUFFER_NORMAL) uniform sampler2DArray u_normal;
layout(binding = TEXTURE_GBUFFER_MATERIAL) uniform sampler2DArray u_material;
layout(binding = TEXTURE_LIT_PRECONVOLVED) uniform sampler2DArray u_preconvolved;  // trilinear

layout(binding = IMAGE_REFLECTION, rgba16f) writeonly uniform image2D o_reflection;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(frame.viewport.xy);
    if (any(greaterThanEqual(p, size))) return;
    GSample g = gbuffer_decode(texelFetch(u_albedo, ivec3(p, 0), 0), texelFetch(u_normal, ivec3(p, 0), 0),
                               texelFetch(u_material, ivec3(p, 0), 0));
    vec3 pos = view_position(vec2(p) + 0.5, texelFetch(u_linear_depth, ivec3(p, 0), 0).r);
    vec3 v = normalize(-pos);
    vec3 reflection = vec3(0.0);
    if (g.covered && g.reflectivity > 0.0) reflection = glossy_environment(reflect(-v, g.normal));
    ivec2 q = min(p / ssr.downscale, ivec2(ssr.trace_width, ssr.trace_height) - 1);
    bool receives = g.covered && g.reflectivity > 0.0 && g.roughness <= ssr.roughness_cutoff;
    if (!receives || texelFetch(u_sample, ivec3(q, 0), 0).x <= 0.0) {
        imageStore(o_reflection, p, vec4(reflection, 1.0));
        return;
    }
    vec3 dir = texelFetch(u_direction, ivec3(q, 0), 0).xyz;
    vec3 env = glossy_unresolved(q, g.normal, v, g.roughness, dir);
    vec4 hit = texelFetch(u_hit, ivec3(q, 0), 0);
    reflection = env;
    if (hit.z > 0.5) {
        int layer = int(hit.z) - 1;
        vec2 p1 = vec2(glossy_origin_pixel(q)) + 0.5;
        float d = length(hit.xy - p1);
        float radius = tan(min(cone_angle(g.roughness, clamp(dot(g.normal, v), 0.0, 1.0)), 1.5)) * d;
        vec3 c;
        if (radius < 0.5) {
            c = texelFetch(u_lit, ivec3(clamp(ivec2(hit.xy), ivec2(0), size - 1), layer), 0).rgb;
        } else {
            float level = max(log2(radius) + ssr.cone_level_bias, 0.0);
            float coverage;
            c = unpremultiply(textureLod(u_preconvolved, vec3(hit.xy * frame.viewport.zw, float(layer)), level), coverage);
            if (coverage <= 1e-6) c = env;
        }
        reflection = mix(env, c, hit.w);
    }
    imageStore(o_reflection, p, vec4(reflection, 1.0));
}
