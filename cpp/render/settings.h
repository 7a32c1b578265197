// The native render settings. Every field is declared once, in settings_fields.def, from which
// this struct, its validation, the Python bindings and ssrlab.Settings, and the shaders' uniform
// block are made. validate() checks every range so that the C++ core never runs on values that
// would hang or crash a pass.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "render/depth_convention.h"

namespace ssr {

enum class TraceMethod { Off, Linear, Hiz, Bvh };
// Where rays screen space cannot resolve go: nothing, the environment, the BVH,
// reflection probes (seed 004's local cube maps, then the environment).
enum class Fallback { None, Environment, Bvh, Probes };
// How the BVH passes (trace_bvh, fallback_bvh, the probes' capture) shadow what they shade.
enum class BvhShadows { Map, Traced };
enum class Sampling { Mirror, Ggx, Vndf, GgxThesisLiteral };
enum class Noise { Pcg, ThesisHash };
enum class ThicknessMode { Constant, RayStep };
enum class ReuseWeighting { Thesis, Brdf };
enum class CompositeMode { Linear, Pbr };
enum class TaaMode { Off, Thesis, Clamped };
enum class Bounces { Single, History };
// What the temporal passes of the reflection reproject it by (passes/reproject_reflection.h).
enum class ReflectionReprojection { Surface, Hit };
enum class Glossy { Stochastic, Cone, BlurMips };
enum class ConeRemainder { Hit, Environment };
// What an unresolved ray's environment is weighted by (passes/specular_occlusion.h).
enum class SpecularOcclusion { Off, Horizon, Exit };
// Denoiser of the resolved reflection (seed 003): none, or SVGF (Schied et al. 2017).
enum class Denoise { None, Svgf };
// How the layered G-buffer is built: depth peeling (one geometry pass per layer), per-pixel
// fragment lists (one geometry pass, then a selection; Yang et al. 2010), or either of the two
// rasterising visibility only (depth and a triangle id; Burns and Hunt 2013) with every attribute
// rebuilt by a compute pass (passes/visibility_buffer.h, gbuffer_attributes.h). 'auto':
// render/auto_choice.h.
enum class DeepGBuffer { Peel, Lists, Visibility, VisibilityLists };
// Whether `d` rasterises visibility only (the visibility_buffer and gbuffer_attributes passes).
inline bool visibility_construction(DeepGBuffer d) {
    return d == DeepGBuffer::Visibility || d == DeepGBuffer::VisibilityLists;
}

// Names <-> values, for Python and for error messages. parse_enum throws std::invalid_argument
// "Settings.<field> must be one of 'a', 'b', got 'x'", listing 'auto' first where `takes_auto`.
template <typename E> E parse_enum(const std::string& field, const std::string& name, bool takes_auto = false);
template <typename E> std::string enum_name(E value);
// Every (value, name) of an enum, in the order Python lists its choices.
template <typename E> const std::vector<std::pair<E, std::string>>& enum_names();

// Flags of a setting in settings_fields.def.
enum SettingFlag : unsigned {
    kAuto = 1u,        // Python also takes 'auto' (its default there), decided per device (auto_choice.h)
    kOffAtZero = 2u,   // 0 is allowed outside [lo, hi] and switches the feature off
    kReference = 4u,   // the setting changes a converged reference image
};

struct RenderSettings {
    // Every field, its default and its range: settings_fields.def (units and meanings there too).
#define SSR_FIELD(kind, ctype, name, def, lo, hi, unit, place, flags, group, doc) ctype name = ctype(def);
#include "render/settings_fields.def"

    // User passes (passes/user_pass.h) a render runs, by name, and their parameters by
    // "<pass>.<param>" (the declared default where absent); checked against the renderer's
    // registered passes (Renderer::check_user_settings).
    struct UserPassSettings {
        std::vector<std::string> passes;
        std::map<std::string, double> params;
    } user;

    // The cone and blur_mips methods trace one mirror ray per pixel and blur its hit (seed 002 4.4,
    // seed 004), whatever rays_per_pixel and sampling say.
    bool one_mirror_ray() const { return glossy != Glossy::Stochastic; }
    // Rays traced per pixel.
    int traced_rays() const { return one_mirror_ray() ? 1 : rays_per_pixel; }
    // These settings as the chain runs them: what a technique overrides written in (one_mirror_ray:
    // rays_per_pixel 1, sampling "mirror"). The shaders see these (ssr_uniforms), and Frame.settings
    // and a sweep's rows report them, so no figure claims work that was not done.
    RenderSettings as_run() const {
        RenderSettings s = *this;
        if (one_mirror_ray()) {
            s.rays_per_pixel = 1;
            s.sampling = Sampling::Mirror;
        }
        return s;
    }

    int trace_width() const { return (width + downscale - 1) / downscale; }
    int trace_height() const { return (height + downscale - 1) / downscale; }

    // Every range (settings_fields.def), downscale's values, then check_rules(); throws
    // std::invalid_argument naming the field.
    void validate() const;
    // The rules between fields (settings_rules.def): throws std::invalid_argument naming the
    // fields, their values, the rule and why, in the words ssrlab.Settings raises.
    void check_rules() const;
};

// A rule between fields, as settings_rules.def declares it: the settings it ties, the rule as
// users read it and what breaks otherwise (the test itself: RenderSettings::check_rules()).
struct SettingsRule {
    std::vector<std::string> fields;
    std::string rule;
    std::string why;
};
const std::vector<SettingsRule>& settings_rules();

// Throws std::invalid_argument "Settings.<field> must be in [lo, hi] unit, got v" (or downscale's
// "must be 1, 2 or 4") unless `value`, a Python float or int compared with the bounds as declared,
// is allowed for the numeric setting `field`: the check validate() makes, which ssrlab.Settings
// forwards.
void check_setting_value(const std::string& field, double value);

// Throws parse_enum's message unless `value` names a choice of the enumerated setting `field`
// ('auto' where the field is flagged kAuto): the one check of a setting's choice, which
// ssrlab.Settings forwards.
void check_setting_choice(const std::string& field, const std::string& value);

// A field's value as Python writes it (repr): 5, 0.5, True, 'bvh'; for messages.
std::string setting_repr(const RenderSettings& s, const std::string& field);

}  // namespace ssr
