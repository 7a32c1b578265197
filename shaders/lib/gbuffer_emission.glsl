// The emitted radiance of a G-buffer sample (glTF emissiveFactor x KHR_materials_emissive_strength,
// times the emissive texture's texel where the material has one), for the passes that shade
// G-buffer texels with lib/shading.glsl (lighting, the BVH fallback's screen hits, the reference's
// own pixel). Without an emissive texture in the scene the factor is found through the object id
// the G-buffer already stores, so the layers need no extra channel; with one (EMISSION_TEXTURE 1,
// FrameFacts::emission_texture) the peeling's shading pass sampled it where the texture
// coordinates are and wrote gbuffer.emission, which the including pass binds by name
// (TEXTURE_GBUFFER_EMISSION).
// Needs scene_data.glsl, gbuffer.glsl.
#ifndef EMISSION_TEXTURE
#define EMISSION_TEXTURE 0
#endif

#if EMISSION_TEXTURE
layout(binding = TEXTURE_GBUFFER_EMISSION) uniform sampler2DArray u_emission;  // gbuffer.emission, by the includer's name

vec3 gbuffer_emission(ivec3 p, GSample g) {
    return g.covered ? texelFetch(u_emission, p, 0).rgb : vec3(0.0);
}
#else
vec3 gbuffer_emission(ivec3 p, GSample g) {
    return g.object_id >= 0 ? materials[objects[g.object_id].material.x].emissive.rgb : vec3(0.0);
}
#endif
