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

// What brdf_cosine(v, l, alpha) (ggx_sampling.glsl) keeps per receiver: its factor that does not
// depend on l, alpha^2 G1(v) / (4 n.v) (0 where v is below the surface). With
// brdf_cosine_over_pdf below, the resolve weighs a reused ray (Stachowiak 2015) without a local
// frame, a half vector or a second G1 per ray.
float brdf_cosine_receiver(float nv, float alpha) {
    return nv > 0.0 ? alpha * alpha * ggx_G1(nv, alpha) / (4.0 * nv) : 0.0;
}

// brdf_cosine(v, l, alpha) / pdf for unit view direction v, light direction l and normal n in
// any one frame; `receiver` = brdf_cosine_receiver(n.v, alpha). The same terms, rearranged
//: with u = v + l, the half vector's cosine is n.u / |u|, so Walter et al.'s D (eq. 33)
// is alpha^2 |u|^4 / (pi k^2) with k = |u x n|^2 + alpha^2 (n.u)^2 (ggx_D's floor pi d^2 >= 1e-12
// scaled by |u|^4), and G1(l) (eq. 34, multiplied by n.l / n.l) is
// 2 c / (c + sqrt(alpha^2 + (1 - alpha^2) c^2)), c = max(n.l, 1e-4) (ggx_G1's floor c^2 >= 1e-8).
// No local frame, half vector or second G1 per ray: one division and one square root. k takes
// the half vector's tangential part from the cross product, not as 1 - (n.h)^2, which cancels
// for smooth surfaces (alpha^2 ~ 1e-4) where D is sharp.
float brdf_cosine_over_pdf(vec3 n, vec3 v, vec3 l, float alpha, float receiver, float pdf) {
    float a2 = alpha * alpha;
    float nl = dot(n, l);
    vec3 u = v + l;
    float s = dot(u, u);
    float nu = dot(n, u);
    vec3 t = cross(u, n);
    float k = dot(t, t) + a2 * nu * nu;
    float c = max(nl, 1e-4);
    float den = max(PI * k * k, 1e-12 * s * s) * (c + sqrt(a2 + (1.0 - a2) * c * c)) * pdf;
    return nl > 0.0 ? receiver * s * s * 2.0 * c / den : 0.0;
}
