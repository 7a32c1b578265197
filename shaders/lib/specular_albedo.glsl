// The GGX lobe's directional albedo in the split-sum form (Karis 2013, "Real Shading in
// Unreal Engine 4"): with Schlick's Fresnel F = F0 + (1 - F0) (1 - v.h)^5,
//     E(v) = integral of f_r(v, l) (n.l) dl = F0 A(n.v, roughness) + B(n.v, roughness),
//     A = E[w (1 - (1 - v.h)^5)],  B = E[w (1 - v.h)^5],
// w the sampler's weight f_r (n.l) / pdf without Fresnel (lib/ggx_sampling.glsl). The table
// of (A, B) is integrated once per renderer by tools/specular_albedo.comp with the very
// sampler the tracers use, over n.v in [0, 1] (columns) and perceptual roughness in [0, 1]
// (rows), cell centres at the range ends so that both ends are exact.
// The including shader declares the table at the frame-wide unit the renderer names:
// layout(binding = TEXTURE_SPECULAR_ALBEDO) uniform sampler2D.

const int SPECULAR_ALBEDO_SIZE = 32;

// Texture coordinates of (n.v, roughness) in the table (bilinear filtering between cells).
vec2 specular_albedo_uv(float NoV, float roughness) {
    vec2 x = clamp(vec2(NoV, roughness), 0.0, 1.0);
    return (x * float(SPECULAR_ALBEDO_SIZE - 1) + 0.5) / float(SPECULAR_ALBEDO_SIZE);
}

// E = F0 A + B for a table entry ab = (A, B).
vec3 specular_albedo(vec3 F0, vec2 ab) {
    return F0 * ab.x + ab.y;
}

// The share of light a surface reflects specularly, one number (Rec. 709 luminance of E):
// the reflectivity r of glTF materials that do not set the thesis's own (seed 000, 2.4.2).
float specular_reflectivity(vec3 F0, vec2 ab) {
    return clamp(dot(specular_albedo(F0, ab), vec3(0.2126, 0.7152, 0.0722)), 0.0, 1.0);
}
