#include "render/settings.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
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
E parse_enum(const std::string& field, const std::string& name, bool takes_auto) {
    std::string known = takes_auto ? "'auto'" : "";
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
    template E parse_enum<E>(const std::string&, const std::string&, bool); \
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
// A float or double as Python's repr writes it: the shortest digits that read back as the same
// value, fixed from 1e-4 up to 1e16 (always with a point), with an exponent outside: 5.0, 0.002,
// 1e-05, 1e+16. A float32 field shows its own digits (0.1f as 0.1, not 0.10000000149011612).
template <typename T>
std::string python_float(T v) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::scientific);  // d.ddde+XX
    const std::string sci(buf, r.ptr);
    const size_t e = sci.find('e');
    const int exp = std::stoi(sci.substr(e + 1));
    const bool negative = sci[0] == '-';
    std::string digits;
    for (char c : sci.substr(0, e))
        if (std::isdigit(static_cast<unsigned char>(c))) digits += c;
    std::string out;
    if (exp >= 16 || exp < -4) {
        out = digits.substr(0, 1) + (digits.size() > 1 ? "." + digits.substr(1) : "") + "e" + (exp < 0 ? "-" : "+") +
              (std::abs(exp) < 10 ? "0" : "") + std::to_string(std::abs(exp));
    } else if (exp < 0) {
        out = "0." + std::string(size_t(-exp - 1), '0') + digits;
    } else if (digits.size() <= size_t(exp) + 1) {
        out = digits + std::string(size_t(exp) + 1 - digits.size(), '0') + ".0";
    } else {
        out = digits.substr(0, size_t(exp) + 1) + "." + digits.substr(size_t(exp) + 1);
    }
    return (negative ? "-" : "") + out;
}

// A bound or value in a message, as Python writes the field's type: an int field's as an integer,
// a float field's with its point (0.0, 1e-06).
std::string number(double v, bool is_float) {
    if (is_float) return python_float(v);
    if (std::isfinite(v) && v == std::floor(v)) {
        char buf[400];  // a double's integer digits, up to 1.8e308
        std::snprintf(buf, sizeof buf, "%.0f", v);
        return buf;
    }
    return python_float(v);
}

// A numeric field's value against its range, as settings_fields.def declares it, and downscale's
// values, which a range cannot say. A float32 field (`as_declared` false) compares with the bounds
// rounded to float: the declared bounds are decimal doubles, 1e-6 as a float is 9.99999997e-7 <
// 1e-6, and comparing in double would reject the declared lower bounds themselves. ssrlab.Settings'
// values are Python floats, compared with the bounds as written (`as_declared`) before they become
// float32.
void check_value(double v, bool as_declared, double lo, double hi, bool is_float, const char* unit, unsigned flags,
                 const char* name) {
    if (std::string(name) == "downscale")
        check(v == 1 || v == 2 || v == 4, "Settings.downscale must be 1, 2 or 4, got " + number(v, false));
    if ((flags & kOffAtZero) && v == 0.0) return;
    const bool rounded = is_float && !as_declared;
    const double lo_f = rounded ? double(float(lo)) : lo, hi_f = rounded ? double(float(hi)) : hi;
    if (std::isfinite(v) && v >= lo_f && v <= hi_f) return;
    std::string msg = std::string("Settings.") + name + " must be in [" + number(lo, is_float) + ", " +
                      number(hi, is_float) + "]";
    if (*unit) msg += std::string(" ") + unit;
    if (flags & kOffAtZero) msg += " (or 0: off)";
    throw std::invalid_argument(msg + ", got " + (rounded ? python_float(float(v)) : number(v, is_float)));
}
}  // namespace

void check_setting_value(const std::string& field, double value) {
#define SSR_VALUE_INT(name, lo, hi, unit, flags) return check_value(value, true, lo, hi, false, unit, flags, #name);
#define SSR_VALUE_UINT SSR_VALUE_INT
#define SSR_VALUE_FLOAT(name, lo, hi, unit, flags) return check_value(value, true, lo, hi, true, unit, flags, #name);
#define SSR_VALUE_BOOL(name, lo, hi, unit, flags) break;
#define SSR_VALUE_ENUM SSR_VALUE_BOOL
#define SSR_FIELD(kind, ctype, name, def, lo, hi, unit, place, flags, group, doc) \
    if (field == #name) do {                                                    \
            SSR_VALUE_##kind(name, lo, hi, unit, flags)                         \
        } while (false);
#include "render/settings_fields.def"
#undef SSR_VALUE_INT
#undef SSR_VALUE_UINT
#undef SSR_VALUE_FLOAT
#undef SSR_VALUE_BOOL
#undef SSR_VALUE_ENUM
    throw std::invalid_argument("Settings." + field + " is not a numeric setting");
}

void RenderSettings::validate() const {
    // Every numeric field's range (settings_fields.def), downscale's values.
#define SSR_CHECK_INT(name, lo, hi, unit, flags) check_value(double(name), false, lo, hi, false, unit, flags, #name);
#define SSR_CHECK_UINT SSR_CHECK_INT
#define SSR_CHECK_FLOAT(name, lo, hi, unit, flags) check_value(double(name), false, lo, hi, true, unit, flags, #name);
#define SSR_CHECK_BOOL(name, lo, hi, unit, flags)
#define SSR_CHECK_ENUM(name, lo, hi, unit, flags)
#define SSR_FIELD(kind, ctype, name, def, lo, hi, unit, place, flags, group, doc) SSR_CHECK_##kind(name, lo, hi, unit, flags)
#include "render/settings_fields.def"
#undef SSR_CHECK_INT
#undef SSR_CHECK_UINT
#undef SSR_CHECK_FLOAT
#undef SSR_CHECK_BOOL
#undef SSR_CHECK_ENUM
    check_rules();
}

namespace {
std::string repr(int v) { return std::to_string(v); }
std::string repr(uint32_t v) { return std::to_string(v); }
std::string repr(float v) { return python_float(v); }
std::string repr(bool v) { return v ? "True" : "False"; }
template <typename E>
std::string repr(E v) {
    return "'" + enum_name(v) + "'";
}

std::vector<std::string> split_fields(const char* fields) {
    std::vector<std::string> out;
    std::string f = fields;
    for (size_t at = 0; at <= f.size();) {
        const size_t comma = std::min(f.find(", ", at), f.size());
        out.push_back(f.substr(at, comma - at));
        at = comma + 2;
    }
    return out;
}
}  // namespace

void check_setting_choice(const std::string& field, const std::string& value) {
#define SSR_CHOICE_INT(name, ctype, flags)
#define SSR_CHOICE_UINT SSR_CHOICE_INT
#define SSR_CHOICE_FLOAT SSR_CHOICE_INT
#define SSR_CHOICE_BOOL SSR_CHOICE_INT
#define SSR_CHOICE_ENUM(name, ctype, flags)                                     \
    if (field == #name) {                                                       \
        if (!((flags) & kAuto) || value != "auto") parse_enum<ctype>(#name, value, (flags) & kAuto); \
        return;                                                                 \
    }
#define SSR_FIELD(kind, ctype, name, def, lo, hi, unit, place, flags, group, doc) SSR_CHOICE_##kind(name, ctype, flags)
#include "render/settings_fields.def"
#undef SSR_CHOICE_INT
#undef SSR_CHOICE_UINT
#undef SSR_CHOICE_FLOAT
#undef SSR_CHOICE_BOOL
#undef SSR_CHOICE_ENUM
    throw std::invalid_argument("Settings." + field + " is not an enumerated setting");
}

std::string setting_repr(const RenderSettings& s, const std::string& field) {
#define SSR_FIELD(kind, ctype, name, def, lo, hi, unit, place, flags, group, doc) \
    if (field == #name) return repr(s.name);
#include "render/settings_fields.def"
    throw std::invalid_argument("Settings has no field '" + field + "'");
}

const std::vector<SettingsRule>& settings_rules() {
    static const std::vector<SettingsRule> rules = [] {
        std::vector<SettingsRule> out;
#define SSR_RULE(fields, rule, ok, why) out.push_back({split_fields(fields), rule, why});
#include "render/settings_rules.def"
        return out;
    }();
    return rules;
}

void RenderSettings::check_rules() const {
    const RenderSettings& s = *this;
    size_t row = 0;
    // "Settings: <rule> is violated (<field>=<value>, ...); <why>": the message ssrlab.Settings raises.
    auto violated = [&s](const SettingsRule& r) {
        std::string got;
        for (const std::string& f : r.fields) got += (got.empty() ? "" : ", ") + f + "=" + setting_repr(s, f);
        throw std::invalid_argument("Settings: " + r.rule + " is violated (" + got + "); " + r.why);
    };
#define SSR_RULE(fields, rule, ok, why) \
    if (!(ok)) violated(settings_rules()[row]);  \
    ++row;
#include "render/settings_rules.def"
}

}  // namespace ssr
