// The G-buffer layer layout (seed 000, 2.2, extended with metallic-roughness):
//   gbuffer.albedo    SRGB8_ALPHA8  rgb base colour, a metallic
//   gbuffer.normal    RGBA16F       xyz view-space unit normal, w perceptual roughness
//   gbuffer.material  RGBA8         r reflectivity, g coverage (1 = a surface), b,a unused
//   gbuffer.depth     DEPTH32F      window depth in the frame's depth convention
// Encoding and decoding are pure functions: the including pass does the texel fetches.

struct GSample {
    vec3 albedo;
    float metallic;
    vec3 normal;  // view space, unit length
    float roughness;
    float reflectivity;
    bool covered;
};

GSample gbuffer_decode(vec4 albedo_metallic, vec4 normal_roughness, vec4 material) {
    GSample g;
    g.albedo = albedo_metallic.rgb;
    g.metallic = albedo_metallic.a;
    g.normal = normalize(normal_roughness.xyz);
    g.roughness = normal_roughness.w;
    g.reflectivity = material.r;
    g.covered = material.g > 0.5;
    return g;
}

void gbuffer_encode(GSample g, out vec4 albedo_metallic, out vec4 normal_roughness, out vec4 material) {
    albedo_metallic = vec4(g.albedo, g.metallic);
    normal_roughness = vec4(normalize(g.normal), g.roughness);
    material = vec4(g.reflectivity, 1.0, 0.0, 0.0);
}
