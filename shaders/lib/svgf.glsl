// Spatiotemporal variance-guided filtering (Schied et al. 2017), as seed 003 denoises its one
// reflection ray per pixel: the math shared by the svgf_* passes. Pure functions: the passes
// fetch the textures.

// Rec. 709 luminance: the quantity whose moments and variance steer the filter (paper, 4.1).
float svgf_luminance(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

// A pixel the denoiser filters: a reflective surface whose reflection rays are random. A
// roughness-0 lobe or mirror sampling traces the same ray every frame: nothing to denoise, and
// blurring it would only remove detail.
bool svgf_noisy(bool covered, float reflectivity, float roughness, bool mirror_sampling) {
    return covered && reflectivity > 0.0 && roughness > 1e-3 && !mirror_sampling;
}

// The 1D B3-spline taps of the a-trous wavelet (paper, 4.3): h = (1, 4, 6, 4, 1) / 16, by |i|.
float svgf_b3(int i) {
    return i == 0 ? 0.375 : (abs(i) == 1 ? 0.25 : 0.0625);
}

// The edge-stopping weight of tap q for pixel p (paper, eq. 3-6):
//   depth:     exp(-|z_p - z_q| / (sigma_z |grad z . (p - q)| + eps)), the difference the local
//              depth gradient does not predict, so a slanted floor keeps its taps;
//   normal:    max(0, n_p . n_q)^sigma_n;
//   luminance: exp(-|l_p - l_q| / (sigma_l sqrt(var_p) + eps)), in standard deviations of the
//              noise, so the filter shrinks where the estimate says the signal is clean.
// `depth_predicted` is |grad z . (p - q)|; eps_z (1e-3 of the depth) keeps a surface facing the
// camera, whose gradient is 0, from rejecting its own rounding.
float svgf_weight(float z_p, float z_q, float depth_predicted, float sigma_z, vec3 n_p, vec3 n_q, float sigma_n,
                  float l_p, float l_q, float luminance_scale) {
    float wz = abs(z_p - z_q) / (sigma_z * depth_predicted + 1e-3 * z_p + 1e-6);
    float wl = abs(l_p - l_q) / (luminance_scale + 1e-10);
    float wn = pow(max(dot(n_p, n_q), 0.0), sigma_n);
    return exp(-wz - wl) * wn;
}

// The screen-space gradient of linear depth at a pixel from its 4 neighbours: per axis the
// smaller one-sided difference, so a silhouette next to the pixel does not pass for a slope.
vec2 svgf_depth_gradient(float z, float z_left, float z_right, float z_down, float z_up) {
    float dl = z - z_left, dr = z_right - z;
    float dd = z - z_down, du = z_up - z;
    return vec2(abs(dl) < abs(dr) ? dl : dr, abs(dd) < abs(du) ? dd : du);
}
