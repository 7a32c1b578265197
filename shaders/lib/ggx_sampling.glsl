// Reflection directions for a rough surface: GGX microfacet normals as the thesis samples
// them (seed 000, 2.3.2), GGX visible normals (Heitz, JCGT 7(4), 2018), and the weight
// and pdf each ray carries (Walter et al., EGSR 2007, with Smith's separable G; thesis
// 2.3.3). All directions are in a frame where the macro normal n is +z; v points from the
// surface toward the viewer. Needs brdf.glsl.

struct BrdfSample {
    vec3 l;        // reflected direction, toward the light that is gathered
    float weight;  // f_r(v, l) (n.l) / pdf(l) without the Fresnel factor; 0: no valid sample
    float pdf;     // solid-angle density of l; 0 for the mirror direction (a Dirac delta)
};

// An orthonormal frame whose third axis is n (Duff et al., JCGT 6(1), 2017: branchless).
mat3 frame_from_normal(vec3 n) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float b = n.x * n.y * a;
    return mat3(vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x), vec3(b, s + n.y * n.y * a, -n.y), n);
}

// Thesis 2.3.2: theta = arctan(alpha sqrt(u1) / sqrt(1 - u1)), phi = 2 pi u2, the inverse CDF
// of GGX's D(m) cos(theta_m); returned as the unit vector (cos phi sin theta, sin phi sin theta, cos theta).
vec3 sample_ggx_normal(vec2 u, float alpha) {
    float tan2 = alpha * alpha * u.x / max(1.0 - u.x, 1e-7);
    float cos_theta = inversesqrt(1.0 + tan2);
    float sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    float phi = 2.0 * PI * u.y;
    return vec3(cos(phi) * sin_theta, sin(phi) * sin_theta, cos_theta);
}

// The thesis's own construction: (cos phi sin theta, sin phi sin theta, 1 - cos theta) added
// to n = (0, 0, 1) and normalised. It is not distributed as D(m) cos(theta_m), so the Walter
// weight below is biased for it; kept to reproduce and measure the thesis.
vec3 sample_ggx_normal_thesis_literal(vec2 u, float alpha) {
    vec3 m = sample_ggx_normal(u, alpha);
    return normalize(vec3(m.xy, 1.0 + (1.0 - m.z)));
}

// Heitz 2018, listing 1: a GGX normal visible from v, pdf G1(v) max(0, v.m) D(m) / v.z.
vec3 sample_vndf(vec3 v, float alpha, vec2 u) {
    vec3 vh = normalize(vec3(alpha * v.x, alpha * v.y, v.z));
    float len2 = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = len2 > 0.0 ? vec3(-vh.y, vh.x, 0.0) * inversesqrt(len2) : vec3(1.0, 0.0, 0.0);
    vec3 t2 = cross(vh, t1);
    float r = sqrt(u.x);
    float phi = 2.0 * PI * u.y;
    float p1 = r * cos(phi);
    float p2 = r * sin(phi);
    float s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * sqrt(max(1.0 - p1 * p1, 0.0)) + s * p2;
    vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(1.0 - p1 * p1 - p2 * p2, 0.0)) * vh;
    return normalize(vec3(alpha * nh.x, alpha * nh.y, max(nh.z, 0.0)));
}

// A reflection direction for view direction v (local frame, v.z > 0), GGX alpha, method
// and two uniform numbers.
BrdfSample sample_reflection(vec3 v, float alpha, int method, vec2 u) {
    BrdfSample s;
    if (method == SAMPLING_MIRROR || alpha < 1e-4) {
        s.l = vec3(-v.xy, v.z);
        s.weight = 1.0;
        s.pdf = 0.0;
        return s;
    }
    vec3 m = method == SAMPLING_VNDF ? sample_vndf(v, alpha, u)
           : method == SAMPLING_GGX_THESIS_LITERAL ? sample_ggx_normal_thesis_literal(u, alpha)
                                                   : sample_ggx_normal(u, alpha);
    float vm = dot(v, m);
    s.l = 2.0 * vm * m - v;  // reflect v about m
    float nl = s.l.z, nv = v.z, nm = m.z;
    if (nl <= 0.0 || vm <= 0.0 || nm <= 0.0) {  // below the surface: no valid sample
        s.weight = 0.0;
        s.pdf = 0.0;
        return s;
    }
    float D = ggx_D(nm, alpha);
    if (method == SAMPLING_VNDF) {
        // pdf(l) = G1(v) D(m) / (4 v.z); weight = G2(l, v) / G1(v) = G1(l) for separable Smith.
        s.pdf = ggx_G1(nv, alpha) * D / (4.0 * nv);
        s.weight = ggx_G1(nl, alpha);
    } else {
        // Walter et al. eq. 38 and 41: pdf(l) = D(m)(m.n) / (4 |v.m|),
        // weight = |v.m| G(l, v, m) / (|v.n| |m.n|).
        s.pdf = D * nm / (4.0 * vm);
        s.weight = vm * ggx_G(nl, nv, alpha) / (nv * nm);
    }
    return s;
}

// The density with which `method` samples direction l (local frame) for view v: the same
// pdf as sample_reflection reports, for a direction sampled elsewhere (neighbour reuse).
float reflection_pdf(vec3 v, vec3 l, float alpha, int method) {
    vec3 h = normalize(v + l);
    float D = ggx_D(max(h.z, 0.0), alpha);
    if (method == SAMPLING_VNDF) return ggx_G1(max(v.z, 1e-4), alpha) * D / (4.0 * max(v.z, 1e-4));
    return D * max(h.z, 0.0) / (4.0 * max(dot(v, h), 1e-4));
}

// f_r(v, l) (n.l) without the Fresnel factor: the integrand the weights estimate.
float brdf_cosine(vec3 v, vec3 l, float alpha) {
    if (l.z <= 0.0 || v.z <= 0.0) return 0.0;
    vec3 h = normalize(v + l);
    return ggx_D(h.z, alpha) * ggx_G(l.z, v.z, alpha) / (4.0 * v.z);
}
