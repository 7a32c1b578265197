#include "render/settings.h"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace ssr {

namespace {
void check(bool ok, const std::string& msg) {
    if (!ok) throw std::invalid_argument(msg);
}
}  // namespace

namespace {
template <typename E>
const std::vector<std::pair<E, std::string>>& names();
template <>
const std::vector<std::pair<TraceMethod, std::string>>& names() {
    static const std::vector<std::pair<TraceMethod, std::string>> n = {
        {TraceMethod::Off, "off"}, {TraceMethod::Linear, "linear"}, {TraceMethod::Hiz, "hiz"}, {TraceMethod::Bvh, "bvh"}};
    return n;
}
template <>
const std::vector<std::pair<Fallback, std::string>>& names() {
    static const std::vector<std::pair<Fallback, std::string>> n = {
        {Fallback::None, "none"}, {Fallback::Environment, "environment"}, {Fallback::Bvh, "bvh"},
        {Fallback::Probes, "probes"}};
    return n;
}
template <>
const std::vector<std::pair<BvhShadows, std::string>>& names() {
    static const std::vector<std::pair<BvhShadows, std::string>> n = {{BvhShadows::Map, "map"},
                                                                      {BvhShadows::Traced, "traced"}};
    return n;
}
template <>
const std::vector<std::pair<DeepGBuffer, std::string>>& names() {
    static const std::vector<std::pair<DeepGBuffer, std::string>> n = {{DeepGBuffer::Peel, "peel"},
                                                                       {DeepGBuffer::Lists, "lists"}};
    return n;
}
template <>
const std::vector<std::pair<Denoise, std::string>>& names() {
    static const std::vector<std::pair<Denoise, std::string>> n = {{Denoise::None, "none"}, {Denoise::Svgf, "svgf"}};
    return n;
}
template <>
const std::vector<std::pair<Sampling, std::string>>& names() {
    static const std::vector<std::pair<Sampling, std::string>> n = {{Sampling::Mirror, "mirror"},
                                                                    {Sampling::Ggx, "ggx"},
                                                                    {Sampling::Vndf, "vndf"},
                                                                    {Sampling::GgxThesisLiteral, "ggx_thesis_literal"}};
    return n;
}
template <>
const std::vector<std::pair<Noise, std::string>>& names() {
    static const std::vector<std::pair<Noise, std::string>> n = {{Noise::Pcg, "pcg"}, {Noise::ThesisHash, "thesis_hash"}};
    return n;
}
template <>
const std::vector<std::pair<ThicknessMode, std::string>>& names() {
    static const std::vector<std::pair<ThicknessMode, std::string>> n = {{ThicknessMode::Constant, "constant"},
                                                                         {ThicknessMode::RayStep, "ray_step"}};
    return n;
}
template <>
const std::vector<std::pair<ReuseWeighting, std::string>>& names() {
    static const std::vector<std::pair<ReuseWeighting, std::string>> n = {{ReuseWeighting::Thesis, "thesis"},
                                                                          {ReuseWeighting::Brdf, "brdf"}};
    return n;
}
template <>
const std::vector<std::pair<CompositeMode, std::string>>& names() {
    static const std::vector<std::pair<CompositeMode, std::string>> n = {{CompositeMode::Linear, "linear"},
                                                                         {CompositeMode::Pbr, "pbr"}};
    return n;
}
template <>
const std::vector<std::pair<TaaMode, std::string>>& names() {
    static const std::vector<std::pair<TaaMode, std::string>> n = {
        {TaaMode::Off, "off"}, {TaaMode::Thesis, "thesis"}, {TaaMode::Clamped, "clamped"}};
    return n;
}
template <>
const std::vector<std::pair<Bounces, std::string>>& names() {
    static const std::vector<std::pair<Bounces, std::string>> n = {{Bounces::Single, "single"},
                                                                   {Bounces::History, "history"}};
    return n;
}
template <>
const std::vector<std::pair<Glossy, std::string>>& names() {
    static const std::vector<std::pair<Glossy, std::string>> n = {
        {Glossy::Stochastic, "stochastic"}, {Glossy::Cone, "cone"}, {Glossy::BlurMips, "blur_mips"}};
    return n;
}
template <>
const std::vector<std::pair<ConeRemainder, std::string>>& names() {
    static const std::vector<std::pair<ConeRemainder, std::string>> n = {{ConeRemainder::Hit, "hit"},
                                                                         {ConeRemainder::Environment, "environment"}};
    return n;
}
template <>
const std::vector<std::pair<SpecularOcclusion, std::string>>& names() {
    static const std::vector<std::pair<SpecularOcclusion, std::string>> n = {
        {SpecularOcclusion::Off, "off"}, {SpecularOcclusion::Horizon, "horizon"}, {SpecularOcclusion::Exit, "exit"}};
    return n;
}
}  // namespace

template <typename E>
E parse_enum(const std::string& field, const std::string& name) {
    std::string known;
    for (const auto& [v, n] : names<E>()) {
        if (n == name) return v;
        known += (known.empty() ? "'" : ", '") + n + "'";
    }
    throw std::invalid_argument("Settings." + field + " must be one of " + known + ", got '" + name + "'");
}

template <typename E>
std::string enum_name(E value) {
    for (const auto& [v, n] : names<E>())
        if (v == value) return n;
    return "?";
}

#define SSR_INSTANTIATE(E) \
    template E parse_enum<E>(const std::string&, const std::string&); \
    template std::string enum_name<E>(E);
SSR_INSTANTIATE(TraceMethod)
SSR_INSTANTIATE(Fallback)
SSR_INSTANTIATE(Denoise)
SSR_INSTANTIATE(DeepGBuffer)
SSR_INSTANTIATE(BvhShadows)
SSR_INSTANTIATE(Sampling)
SSR_INSTANTIATE(Noise)
SSR_INSTANTIATE(ThicknessMode)
SSR_INSTANTIATE(ReuseWeighting)
SSR_INSTANTIATE(CompositeMode)
SSR_INSTANTIATE(TaaMode)
SSR_INSTANTIATE(Bounces)
SSR_INSTANTIATE(Glossy)
SSR_INSTANTIATE(ConeRemainder)
SSR_INSTANTIATE(SpecularOcclusion)
#undef SSR_INSTANTIATE

void RenderSettings::validate() const {
    check(width >= 1 && width <= 16384, "Settings.width must be in [1, 16384] pixels, got " + std::to_string(width));
    check(height >= 1 && height <= 16384, "Settings.height must be in [1, 16384] pixels, got " + std::to_string(height));
    check(layers >= 1 && layers <= 16, "Settings.layers must be in [1, 16], got " + std::to_string(layers));
    check(deep_gbuffer_budget >= 0 && deep_gbuffer_budget <= (1 << 20),
          "Settings.deep_gbuffer_budget must be 0 (the device's limit) or in [1, 1048576] MiB, got " + std::to_string(deep_gbuffer_budget));
    check(std::isfinite(min_separation) && min_separation >= 0.0f && min_separation <= 1e6f,
          "Settings.min_separation must be finite and in [0, 1e6] world units, got " + std::to_string(min_separation));
    check(shadow_map_size == 0 || (shadow_map_size >= 16 && shadow_map_size <= 16384),
          "Settings.shadow_map_size must be 0 (off) or in [16, 16384], got " + std::to_string(shadow_map_size));
    check(std::isfinite(shadow_normal_offset) && shadow_normal_offset >= 0.0f,
          "Settings.shadow_normal_offset must be finite and >= 0");
    check(shadow_pcf_radius >= 0 && shadow_pcf_radius <= 4,
          "Settings.shadow_pcf_radius must be in [0, 4], got " + std::to_string(shadow_pcf_radius));
    // The fields are float32 while the documented bounds are decimal doubles: 1e-6 as a float
    // is 9.99999997e-7 < 1e-6, so comparing in double rejected the documented lower bounds
    // themselves. Bounds are rounded to float first, the precision of the field.
    auto range = [](double v, double lo_d, double hi_d, const char* name) {
        const double lo = double(float(lo_d)), hi = double(float(hi_d));
        check(std::isfinite(v) && v >= lo && v <= hi,
              std::string("Settings.") + name + " must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                  "], got " + std::to_string(v));
    };
    range(rays_per_pixel, 1, 32, "rays_per_pixel");
    range(stride, 1, 64, "stride");
    range(jitter, 0, 1, "jitter");
    range(max_steps, 1, 100000, "max_steps");
    range(max_distance, 1e-3, 1e7, "max_distance");
    range(origin_bias, 0, 1, "origin_bias");
    range(thickness, 0, 1e6, "thickness");
    range(thickness_scale, 0, 1e3, "thickness_scale");
    range(refine_steps, 0, 16, "refine_steps");
    range(hiz_start_level, 0, 15, "hiz_start_level");
    range(hiz_stop_level, 0, 15, "hiz_stop_level");
    range(hiz_max_level, 0, 15, "hiz_max_level");
    check(hiz_stop_level <= hiz_max_level,
          "Settings.hiz_stop_level (" + std::to_string(hiz_stop_level) + ") must be <= Settings.hiz_max_level (" +
              std::to_string(hiz_max_level) + ")");
    range(hiz_linear_steps, 0, 64, "hiz_linear_steps");
    range(hiz_crossing_offset, 1e-5, 0.5, "hiz_crossing_offset");
    check(downscale == 1 || downscale == 2 || downscale == 4,
          "Settings.downscale must be 1, 2 or 4, got " + std::to_string(downscale));
    range(reuse_radius, 0, 2, "reuse_radius");
    range(edge_depth_sigma, 1e-6, 1e3, "edge_depth_sigma");
    range(edge_normal_power, 0, 1024, "edge_normal_power");
    range(fade_border, 0, 0.5, "fade_border");
    range(fade_camera_start, -1, 1, "fade_camera_start");
    range(fade_camera_end, -1, 1, "fade_camera_end");
    range(fade_distance_start, 0, 1e7, "fade_distance_start");
    range(fade_distance_end, 0, 1e7, "fade_distance_end");
    range(roughness_cutoff, 0, 1, "roughness_cutoff");
    range(classify_facing, 0, 1, "classify_facing");
    range(variance_threshold, 0, 1e3, "variance_threshold");
    check(!variance_rays || (adaptive_rays && glossy == Glossy::Stochastic &&
                             (method == TraceMethod::Linear || method == TraceMethod::Hiz)),
          "Settings.variance_rays adds the rays adaptive_rays left out, for the screen-space tracers' stochastic "
          "rays: it needs adaptive_rays=True, glossy='stochastic' and method 'linear' or 'hiz'");
    range(temporal_max_history, 1, 1024, "temporal_max_history");
    range(reject_depth, 0, 10, "reject_depth");
    range(reject_normal, -1, 1, "reject_normal");
    range(temporal_clamp, 0, 16, "temporal_clamp");
    range(taa_history_weight, 0, 0.99, "taa_history_weight");
    range(cone_max_samples, 1, 64, "cone_max_samples");
    range(cone_level_bias, -4, 4, "cone_level_bias");
    range(svgf_max_history, 1, 1024, "svgf_max_history");
    range(svgf_iterations, 0, 8, "svgf_iterations");
    range(svgf_sigma_depth, 1e-3, 1e3, "svgf_sigma_depth");
    range(svgf_sigma_normal, 0, 1024, "svgf_sigma_normal");
    range(svgf_sigma_luminance, 1e-3, 1e3, "svgf_sigma_luminance");
    // SVGF accumulates its own history; a second accumulation after it would only add lag.
    check(denoise != Denoise::Svgf || !temporal_reflections,
          "Settings.denoise 'svgf' accumulates its own history: it needs Settings.temporal_reflections off");
    range(probe_size, 8, 1024, "probe_size");
    range(probe_grid, 1, 4, "probe_grid");
    // The BVH tracer and the BVH fallback hand their radiance to the resolve.
    check(method != TraceMethod::Bvh || glossy == Glossy::Stochastic,
          "Settings.method 'bvh' needs Settings.glossy 'stochastic' (cone and blur_mips read screen-space hits)");
    check(!temporal_ray_reuse ||
              (method != TraceMethod::Bvh && fallback != Fallback::Bvh && fallback != Fallback::Probes),
          "Settings.temporal_ray_reuse does not reuse BVH-traced rays yet: it needs Settings.method other than "
          "'bvh' and Settings.fallback other than 'bvh' and 'probes'");
    check((fallback != Fallback::Bvh && fallback != Fallback::Probes) || glossy == Glossy::Stochastic,
          "Settings.fallback 'bvh' and 'probes' need Settings.glossy 'stochastic' (cone and blur_mips read screen-space hits)");
}

}  // namespace ssr
