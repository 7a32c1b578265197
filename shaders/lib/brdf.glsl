// Microfacet BRDF terms: GGX distribution and Smith masking (Walter et al., EGSR 2007),
// Schlick's Fresnel. alpha is GGX's roughness parameter (alpha = perceptual roughness^2).

const float PI = 3.14159265358979;

// Walter et al. eq. 33: D(m) for a microfacet normal with cos(theta_m) = NoH.
float ggx_D(float NoH, float alpha) {
    float a2 = alpha * alpha;
    float d = NoH * NoH * (a2 - 1.0) + 1.0;
    return a2 / max(PI * d * d, 1e-12);
}

// Walter et al. eq. 34 (the thesis's G1, seed 000, 2.3.3) without the chi+ factor:
// G1(v) = 2 / (1 + sqrt(1 + alpha^2 tan^2 theta_v)).
float ggx_G1(float NoV, float alpha) {
    float c2 = max(NoV * NoV, 1e-8);
    float tan2 = max(1.0 - c2, 0.0) / c2;
    return 2.0 / (1.0 + sqrt(1.0 + alpha * alpha * tan2));
}

// Separable Smith shadowing-masking, G(i, o, m) ~ G1(i, m) G1(o, m) (thesis 2.3.3).
float ggx_G(float NoL, float NoV, float alpha) {
    return ggx_G1(NoL, alpha) * ggx_G1(NoV, alpha);
}

vec3 fresnel_schlick(vec3 F0, float cos_theta) {
    float f = pow(clamp(1.0 - cos_theta, 0.0, 1.0), 5.0);
    return F0 + (1.0 - F0) * f;
}

// Specular reflectance at normal incidence for the metallic workflow (glTF 2.0).
vec3 specular_f0(vec3 base_color, float metallic) {
    return mix(vec3(0.04), base_color, metallic);
}

// Roughness floor so that a perfectly smooth material still has a finite GGX lobe for
// punctual lights.
float ggx_alpha(float perceptual_roughness) {
    float r = max(perceptual_roughness, 0.03);
    return r * r;
}
