#version 450 core
// cone_trace (seed 002, 4.4.5 and 4.5.5): glossy reflections from one mirror ray per pixel.
// The Hi-Z trace found where the mirror ray R hits; seen on screen, the cone of half-angle
// theta around R (lib/cone_angle.glsl: the angle holding half of the GGX lobe, from
// roughness and N.V) is an isosceles triangle from the ray's origin P1 to its hit P2. The
// pass samples the circles inscribed in ever smaller triangles, from the hit end toward the
// origin (front to back along the reflected light's path back to the eye: the hit first),
// each at the mip level of its radius (log2 r), reading trilinearly
//   - the pre-convolved colour of the hit layer (premultiplied by coverage, so uncovered
//     pixels add nothing), and
//   - the pre-integrated visibility of that layer (coverage and depth gaps, 4.4.2),
// and weighs each sample by visibility times how much the cone's sphere there overlaps the
// Hi-Z cell's slab [min, max + thickness] (0 above it or behind it, 1 once its centre is
// inside, linear within its radius). The first circle is centred on the hit (the triangle
// reaches one radius past it) and sits on the surface the trace found: its overlap counts
// fully. Weights accumulate until they reach 1. What remains comes from the environment in
// the chapter; by default (Settings.cone_remainder="hit") from the hit circle's colour
// instead, because in a closed room the sky is the wrong answer at every silhouette
// (measured: README "Glossy methods"). Misses and the faded part of a hit (seed 002, 4.6.1)
// take the environment averaged over the GGX lobe (lib/glossy_common.glsl: 16 fixed VNDF
// directions, a pre-filtered environment by quadrature, for constant, sky and map
// environments alike). A cone narrower than half a pixel at the hit is a mirror: it reads
// the lit layer and the mirror direction's environment exactly as the resolve does, so at
// roughness 0 the pass equals mirror tracing.
//
// Deep layers: the trace finds the hit on any layer; the cone then reads the colour,
// visibility and Hi-Z of that one layer, so a reflection of a surface hidden behind layer 0
// blurs with its own layer's neighbours, not with what covers it on screen.
#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/ssr_settings.glsl"
#include "../lib/gbuffer.glsl"
#include "../lib/environment.glsl"
#include "../lib/brdf.glsl"
#include "../lib/random.glsl"
#include "../lib/ggx_sampling.glsl"
#include "../lib/screen_ray.glsl"
#include "../lib/hiz_cells.glsl"
#include "../lib/cone_angle.glsl"
#include "../lib/cone_geometry.glsl"
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
layout(binding = TEXTURE_VISIBILITY) uniform sampler2DArray u_visibility;    // trilinear
layout(binding = TEXTURE_HIZ) uniform sampler2DArray u_hiz;          // (min s, max s), texelFetch

layout(binding = IMAGE_REFLECTION, rgba16f) writeonly uniform image2D o_reflection;

ivec2 hiz_level_size(int level) {
    return max(ivec2(frame.viewport.xy) >> level, ivec2(1));
}

// Overlap of the cone's sphere (view depth z, radius rad) with a Hi-Z cell's slab.
float sphere_overlap(vec2 pixel, int level, int layer, float z, float rad) {
    vec2 mm = texelFetch(u_hiz, ivec3(hiz_cell(pixel, level), layer), level).xy;
    if (mm.x > mm.y) return 0.0;  // the layer covers nothing in this cell
    float front = view_depth_of_screen(mm.x), back = view_depth_of_screen(mm.y) + ssr.thickness;
    rad = max(rad, 1e-5 * z);
    return clamp((z + rad - front) / rad, 0.0, 1.0) * clamp((back - (z - rad)) / rad, 0.0, 1.0);
}

// Pre-convolved colour (premultiplied) and visibility over a footprint of radius r around
// `at`: a circle, or with Settings.cone_stretch an ellipse r / sqrt(N.V) long along the
// ray's screen direction `unit` and r sqrt(N.V) wide (seed 002, 4.6.8: the GGX lobe spreads
// 1 / N.V more in the plane of incidence than across it, at equal area), taken as up to 4
// samples along `unit` at the narrow side's level.
void footprint(vec2 at, vec2 unit, float r, float n_dot_v, int layer, out vec4 colour, out float visibility) {
    float along = r, across = r;
    if (ssr.cone_stretch != 0) {
        float s = min(inversesqrt(max(n_dot_v, 1e-4)), 2.0);  // at most 4:1
        along = r * s;
        across = r / s;
    }
    float level = max(log2(max(across, 1e-6)) + ssr.cone_level_bias, 0.0);
    int n = clamp(int(ceil(along / max(across, 1e-6))), 1, 4);
    colour = vec4(0.0);
    visibility = 0.0;
    for (int k = 0; k < n; ++k) {
        float f = n == 1 ? 0.0 : (float(k) / float(n - 1) * 2.0 - 1.0) * (along - across);
        vec3 uv = vec3((at + unit * f) * frame.viewport.zw, float(layer));
        colour += textureLod(u_preconvolved, uv, level);
        visibility += textureLod(u_visibility, uv, level).r;
    }
    colour /= float(n);
    visibility /= float(n);
}

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
    vec4 smp = texelFetch(u_sample, ivec3(q, 0), 0);
    bool receives = g.covered && g.reflectivity > 0.0 && g.roughness <= ssr.roughness_cutoff;
    if (!receives || smp.x <= 0.0) {  // no ray (not reflective, too rough, seen edge-on)
        imageStore(o_reflection, p, vec4(reflection, 1.0));
        return;
    }
    vec3 dir = texelFetch(u_direction, ivec3(q, 0), 0).xyz;
    vec3 env = glossy_unresolved(q, g.normal, v, g.roughness, dir);
    vec4 hit = texelFetch(u_hit, ivec3(q, 0), 0);
    reflection = env;
    if (hit.z > 0.5) {
        int layer = int(hit.z) - 1;
        // The ray in screen space (pixels, screen depth), as the tracer set it up.
        ivec2 po = glossy_origin_pixel(q);
        vec3 pv = view_position(vec2(po) + 0.5, texelFetch(u_linear_depth, ivec3(po, 0), 0).r);
        vec3 origin = pv + g.normal * (ssr.origin_bias * -pv.z);
        float len = ray_length_in_front_of_near(origin, dir, ssr.max_distance);
        vec3 a = view_to_pixel(origin), b = view_to_pixel(origin + dir * len);
        vec3 o = vec3(a.xy, screen_depth_of_view(-origin.z));
        vec3 e = vec3(b.xy, screen_depth_of_view(-(origin + dir * len).z));
        vec3 sv = e - o;
        float sv2 = max(dot(sv.xy, sv.xy), 1e-12);

        vec2 p1 = o.xy, p2 = hit.xy;
        float adjacent = length(p2 - p1);
        vec2 unit = adjacent > 0.0 ? (p2 - p1) / adjacent : vec2(0.0);
        float n_dot_v = clamp(dot(g.normal, v), 0.0, 1.0);
        float theta = cone_angle(g.roughness, n_dot_v);
        // The first triangle reaches past the hit so that its in-circle is centred on the hit
        // (in the chapter the hit is the triangle's base, which centres the largest circle
        // one radius short of it, toward the origin: measured worse at every roughness).
        adjacent /= 1.0 - isosceles_inradius(isosceles_opposite(1.0, theta), 1.0);
        float focal = frame.proj[1][1] * frame.viewport.y * 0.5;  // pixels per unit at view depth 1
        int max_level = textureQueryLevels(u_hiz) - 1;
        vec3 sum = vec3(0.0), first = env;
        float total = 0.0;
        for (int i = 0; i < ssr.cone_max_samples && (i == 0 || adjacent > 0.5) && total < 1.0; ++i) {
            float r = isosceles_inradius(isosceles_opposite(adjacent, theta), adjacent);
            vec2 at = p1 + unit * (adjacent - r);
            vec3 c;
            float w;
            if (i == 0 && r < 0.5) {
                // A mirror: the hit's own pixel, as the resolve reads it.
                c = texelFetch(u_lit, ivec3(clamp(ivec2(hit.xy), ivec2(0), size - 1), layer), 0).rgb;
                w = 1.0;
            } else {
                float level = max(log2(max(r, 1e-6)) + ssr.cone_level_bias, 0.0);
                vec4 premultiplied;
                float coverage, visibility;
                footprint(at, unit, r, n_dot_v, layer, premultiplied, visibility);
                c = unpremultiply(premultiplied, coverage);
                float overlap = 1.0;
                if (i > 0) {
                    // The ray's depth at the circle's centre, and the sphere's radius there.
                    float t = dot(at - o.xy, sv.xy) / sv2;
                    float z = view_depth_of_screen(o.z + sv.z * t);
                    int cell_level = clamp(int(floor(level + 0.5)), 0, max_level);
                    overlap = sphere_overlap(at, cell_level, layer, z, r * z / focal);
                }
                w = coverage > 1e-6 ? max(visibility, i == 0 ? 1e-6 : 0.0) * overlap : 0.0;
            }
            if (i == 0 && w > 0.0) first = c;
            w = min(w, 1.0 - total);
            sum += w * c;
            total += w;
            adjacent = isosceles_next_adjacent(adjacent, r);
        }
        // The remainder of the cone from the hit circle or the environment
        // (Settings.cone_remainder); the faded share from the environment (4.6.1).
        vec3 remainder = ssr.cone_remainder == CONE_REMAINDER_HIT ? first : env;
        reflection = mix(env, sum + (1.0 - total) * remainder, hit.w);
    }
    imageStore(o_reflection, p, vec4(reflection, 1.0));
}
