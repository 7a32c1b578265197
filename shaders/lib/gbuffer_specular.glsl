// A dielectric's F0 at a G-buffer sample (KHR_materials_ior / _specular), for the passes that
// take F0 from the G-buffer (the lighting through lib/shading.glsl, the BVH fallback's screen
// hits, the reference's own pixel, the PBR composite). Without a specular texture in the scene it
// is the material's factor value, found through the object id the G-buffer already stores, so the
// layers need no extra channel; with one (SPECULAR_TEXTURE 1, FrameFacts::specular_texture) the
// peeling's shading pass sampled the textures where the texture coordinates are and wrote every
// surface's F0 to gbuffer.specular, which the including pass binds by name
// (TEXTURE_GBUFFER_SPECULAR).
// Needs scene_data.glsl, gbuffer.glsl.
#ifndef SPECULAR_TEXTURE
#define SPECULAR_TEXTURE 0
#endif

#if SPECULAR_TEXTURE
layout(binding = TEXTURE_GBUFFER_SPECULAR) uniform sampler2DArray u_gbuffer_specular;  // gbuffer.specular, by the includer's name

vec3 gbuffer_dielectric_f0(ivec3 p, GSample g) {
    return g.covered ? texelFetch(u_gbuffer_specular, p, 0).rgb : vec3(0.04);
}
#else
vec3 gbuffer_dielectric_f0(ivec3 p, GSample g) {
    return g.object_id >= 0 ? materials[objects[g.object_id].material.x].dielectric_f0.rgb : vec3(0.04);
}
#endif
