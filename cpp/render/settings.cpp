#include "render/settings.h"

#include <charconv>
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
        {TraceMethod::Linear, "linear"}, {TraceMethod::Hiz, "hiz"}, {TraceMethod::Bvh, "bvh"}, {TraceMethod::Off, "off"}};
    return n;
}
template <>
const std::vector<std::pair<DepthMode, std::string>>& names() {
    static const std::vector<std::pair<DepthMode, std::string>> n = {{DepthMode::Standard, "standard"},
                                                                     {DepthMode::ReversedZ, "reversed_z"}};
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
                                                                       {DeepGBuffer::Lists, "lists"},
                                                                       {DeepGBuffer::Visibility, "visibility"},
                                                                       {DeepGBuffer::VisibilityLists, "visibility_lists"}};
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
const std::vector<std::pair<ReflectionReprojection, std::string>>& names() {
    static const std::vector<std::pair<ReflectionReprojection, std::string>> n = {
        {ReflectionReprojection::Surface, "surface"}, {ReflectionReprojection::Hit, "hit"}};
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

template <typename E>
const std::vector<std::pair<E, std::string>>& enum_names() {
    return names<E>();
}

#define SSR_INSTANTIATE(E) \
    template E parse_enum<E>(const std::string&, const std::string&); \
    template std::string enum_name<E>(E); \
    template const std::vector<std::pair<E, std::string>>& enum_names<E>();
SSR_INSTANTIATE(DepthMode)
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
SSR_INSTANTIATE(ReflectionReprojection)
SSR_INSTANTIATE(Glossy)
SSR_INSTANTIATE(ConeRemainder)
SSR_INSTANTIATE(SpecularOcclusion)
#undef SSR_INSTANTIATE

namespace {
// A bound or value in a message: a whole number as an integer, others in their shortest round-trip form.
std::string number(double v, bool is_float) {
    if (!is_float && std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 1e18)
        return std::to_string((long long)v);
    char buf[64];
    const auto r = is_float ? std::to_chars(buf, buf + sizeof buf, float(v)) : std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}

// The range of a numeric field, as settings_fields.def declares it. The fields are float32 while
// the declared bounds are decimal doubles: 1e-6 as a float is 9.99999997e-7 < 1e-6, so comparing
// in double would reject the declared lower bounds themselves. Bounds are rounded to the field's
// precision first.
void check_range(double v, double lo, double hi, bool is_float, const char* unit, unsigned flags, const char* name) {
    if ((flags & kOffAtZero) && v == 0.0) return;
    const double lo_f = is_float ? double(float(lo)) : lo, hi_f = is_float ? double(float(hi)) : hi;
    if (std::isfinite(v) && v >= lo_f && v <= hi_f) return;
    std::string msg = std::string("Settings.") + name + " must be in [" + number(lo, false) + ", " + number(hi, false) + "]";
    if (*unit) msg += std::string(" ") + unit;
    if (flags & kOffAtZero) msg += " (or 0: off)";
    throw std::invalid_argument(msg + ", got " + number(v, is_float));
}
}  // namespace

void RenderSettings::validate() const {
    // Every numeric field's range (settings_fields.def).
#define SSR_CHECK_INT(name, lo, hi, unit, flags) check_range(double(name), lo, hi, false, unit, flags, #name);
#define SSR_CHECK_UINT SSR_CHECK_INT
#define SSR_CHECK_FLOAT(name, lo, hi, unit, flags) check_range(double(name), lo, hi, true, unit, flags, #name);
#define SSR_CHECK_BOOL(name, lo, hi, unit, flags)
#define SSR_CHECK_ENUM(name, lo, hi, unit, flags)
#define SSR_FIELD(kind, ctype, name, def, lo, hi, unit, place, flags, group, doc) SSR_CHECK_##kind(name, lo, hi, unit, flags)
#include "render/settings_fields.def"
#undef SSR_CHECK_INT
#undef SSR_CHECK_UINT
#undef SSR_CHECK_FLOAT
#undef SSR_CHECK_BOOL
#undef SSR_CHECK_ENUM

    // Rules between fields, and values a range cannot say.
    check(downscale == 1 || downscale == 2 || downscale == 4,
          "Settings.downscale must be 1, 2 or 4, got " + std::to_string(downscale));
    check(hiz_stop_level <= hiz_max_level,
          "Settings.hiz_stop_level (" + std::to_string(hiz_stop_level) + ") must be <= Settings.hiz_max_level (" +
              std::to_string(hiz_max_level) + ")");
    check(!variance_rays || (adaptive_rays && glossy == Glossy::Stochastic &&
                             (method == TraceMethod::Linear || method == TraceMethod::Hiz)),
          "Settings.variance_rays adds the rays adaptive_rays left out, for the screen-space tracers' stochastic "
          "rays: it needs adaptive_rays=True, glossy='stochastic' and method 'linear' or 'hiz'");
    // SVGF accumulates its own history; a second accumulation after it would only add lag.
    check(denoise != Denoise::Svgf || !temporal_reflections,
          "Settings.denoise 'svgf' accumulates its own history: it needs Settings.temporal_reflections off");
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
