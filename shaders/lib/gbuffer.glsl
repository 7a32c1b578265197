// The G-buffer layer layout (seed 000, 2.2, extended with metallic-roughness):
//   gbuffer.albedo    SRGB8_ALPHA8  rgb base colour, a metallic
//   gbuffer.normal    RGBA16F       xyz view-space unit normal, w perceptual roughness
//   gbuffer.material  RGBA8         r reflectivity, g coverage (1 = a surface), b,a object id + 1
//                                   (low and high byte; 0 = none)
//   gbuffer.depth     DEPTH32F      window depth in the frame's depth convention (R32F, stored by
//                                   compute, with deep_gbuffer "visibility_lists": sampled alike, .r)
// Encoding and decoding are pure functions: the including pass does the texel fetches.

struct GSample {
    vec3 albedo;
    float metallic;
    vec3 normal;  // view space, unit length
    float roughness;
    float reflectivity;
    bool covered;
    int object_id;  // index of the scene object, -1 for none
};

// The object id a gbuffer.material texel holds (-1: none).
int gbuffer_object_id(vec4 material) {
    return int(round(material.b * 255.0)) + 256 * int(round(material.a * 255.0)) - 1;
}

GSample gbuffer_decode(vec4 albedo_metallic, vec4 normal_roughness, vec4 material) {
    GSample g;
    g.albedo = albedo_metallic.rgb;
    g.metallic = albedo_metallic.a;
    g.normal = normalize(normal_roughness.xyz);
    g.roughness = normal_roughness.w;
    g.reflectivity = material.r;
    g.covered = material.g > 0.5;
    g.object_id = gbuffer_object_id(material);
    return g;
}

void gbuffer_encode(GSample g, out vec4 albedo_metallic, out vec4 normal_roughness, out vec4 material) {
    albedo_metallic = vec4(g.albedo, g.metallic);
    normal_roughness = vec4(normalize(g.normal), g.roughness);
    int id = g.object_id + 1;
    material = vec4(g.reflectivity, 1.0, float(id & 255) / 255.0, float((id >> 8) & 255) / 255.0);
}
