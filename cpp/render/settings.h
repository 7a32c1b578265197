// The native mirror of ssrlab.Settings (python/ssrlab/settings.py holds the documentation,
// units, defaults and validation users see). validate() repeats the range checks so that
// the C++ core never runs on values that would hang or crash a pass.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "render/depth_convention.h"

namespace ssr {

enum class TraceMethod { Off, Linear, Hiz, Bvh };
// Where rays screen space cannot resolve go: nothing, the environment, the BVH,
// reflection probes (seed 004's local cube maps, then the environment).
enum class Fallback { None, Environment, Bvh, Probes };
// How the BVH passes (trace_bvh, fallback_bvh, the probes' capture) shadow what they shade.
enum class BvhShadows { Map, Traced };
enum class Sampling { Mirror, Ggx, Vndf, GgxThesisLiteral };  // order = SAMPLING_* in ssr_settings.glsl
enum class Noise { Pcg, ThesisHash };
enum class ThicknessMode { Constant, RayStep };
enum class ReuseWeighting { Thesis, Brdf };
enum class CompositeMode { Linear, Pbr };
enum class TaaMode { Off, Thesis, Clamped };
enum class Bounces { Single, History };
enum class Glossy { Stochastic, Cone, BlurMips };  // order = GLOSSY_* in ssr_settings.glsl
enum class ConeRemainder { Hit, Environment };     // order = CONE_REMAINDER_*
// What an unresolved ray's environment is weighted by (passes/specular_occlusion.h).
enum class SpecularOcclusion { Off, Horizon, Exit };
// Denoiser of the resolved reflection (seed 003): none, or SVGF (Schied et al. 2017).
enum class Denoise { None, Svgf };
// How the layered G-buffer is built: depth peeling (one geometry pass per layer) or per-pixel
// fragment lists (one geometry pass, then a selection; Yang et al. 2010). Python resolves "auto".
enum class DeepGBuffer { Peel, Lists };

// Names <-> values, for Python and for error messages.
template <typename E> E parse_enum(const std::string& field, const std::string& name);
template <typename E> std::string enum_name(E value);

struct RenderSettings {
    // Image
    int width = 640;   // pixels
    int height = 360;  // pixels

    // Deep G-buffer (seed 000, 1.5.1 and 2.2)
    int layers = 1;                 // depth-peeled layers, 1..16
    bool backface_culling = false;  // off as in the thesis: back faces fill deeper layers
    DepthMode depth_mode = DepthMode::Standard;
    DeepGBuffer deep_gbuffer = DeepGBuffer::Peel;
    int deep_gbuffer_budget = 0;  // "lists": MiB the fragment store may take (0: the device's limit); beyond it, peel

    // Direct lighting
    int shadow_map_size = 2048;         // texels per side; 0 turns shadows off
    float shadow_normal_offset = 1.5f;  // receiver offset along its normal, in shadow-map texels
    int shadow_pcf_radius = 1;          // PCF kernel (2r+1)^2 hardware-filtered taps

    // Screen-space reflections (seed 000 section 2, seed 002 sections 4.4-4.7); units and
    // meanings in python/ssrlab/settings.py.
    TraceMethod method = TraceMethod::Linear;
    Fallback fallback = Fallback::Environment;
    bool fallback_confidence = true;  // fallback "bvh": retrace screen-space hits failing the confidence test
    BvhShadows bvh_shadows = BvhShadows::Map;  // the frame's shadow map, or a traced shadow ray
    int probe_size = 128;  // fallback "probes": cube-map face size, texels
    int probe_grid = 1;    // fallback "probes", scene without probes: g x g x g probes over the bounds (1: centre)
    int rays_per_pixel = 1;
    Sampling sampling = Sampling::Ggx;
    Noise noise = Noise::Pcg;
    bool hammersley = true;
    uint32_t seed = 0;
    float stride = 1.0f;
    float jitter = 1.0f;
    int max_steps = 512;
    float max_distance = 1000.0f;
    float origin_bias = 0.002f;
    float thickness = 0.2f;
    ThicknessMode thickness_mode = ThicknessMode::Constant;
    float thickness_scale = 1.0f;
    int refine_steps = 0;
    int hiz_start_level = 1;
    int hiz_stop_level = 0;
    int hiz_max_level = 12;
    int hiz_linear_steps = 0;
    bool hiz_use_max = true;
    float hiz_crossing_offset = 0.01f;
    int downscale = 1;
    int reuse_radius = 1;
    ReuseWeighting reuse_weighting = ReuseWeighting::Brdf;
    bool edge_aware = true;
    float edge_depth_sigma = 0.05f;
    float edge_normal_power = 16.0f;
    float fade_border = 0.05f;
    float fade_camera_start = 0.5f;
    float fade_camera_end = 0.9f;
    float fade_distance_start = 0.0f;
    float fade_distance_end = 0.0f;
    float roughness_cutoff = 1.0f;
    CompositeMode composite = CompositeMode::Linear;

    // Frames in time (seed 000 4.4, seed 002 4.6.5 and 4.7.4); units in python/ssrlab/settings.py.
    bool temporal_reflections = false;   // reproject + temporal passes: accumulate the resolved reflection
    int temporal_max_history = 32;       // frames; the current frame weighs 1 / min(history, this)
    float reject_depth = 0.05f;          // relative depth difference that rejects history; 0: off
    float temporal_clamp = 0.0f;         // reflection history clamped to mean +- this many sigma (YCoCg); 0: off
    float reject_normal = 0.9f;          // minimum normal cosine that keeps history; -1: off
    bool reject_offscreen = true;        // history outside the previous image is rejected
    TaaMode taa = TaaMode::Off;          // sub-pixel jitter + the taa pass (seed 000, 2.5)
    float taa_history_weight = 0.9f;     // clamped TAA: weight of the clamped history
    Bounces bounces = Bounces::Single;   // history: hits fetch the previous final colour (seed 002, 4.6.4)
    bool skip = true;             // classify + indirect trace over the ray list
    float classify_facing = 0.0f;  // skip: minimum n.v of a pixel that gets rays
    bool adaptive_rays = false;    // rays per pixel follow roughness within rays_per_pixel
    bool variance_rays = false;    // adaptive_rays: a second trace adds rays where the neighbourhood disagrees
    float variance_threshold = 0.25f;  // relative std. dev. of the neighbourhood's ray luminance that adds rays
    bool temporal_ray_reuse = false;     // resolve also reuses the previous frame's reprojected rays (seed 000, 4.4)
    // Glossy reflections (seed 002, 4.4.2-4.4.5): stochastic GGX rays + resolve, or one
    // mirror ray per pixel with a cone through pre-convolved mips, or one ray and a blurred mip.
    Glossy glossy = Glossy::Stochastic;
    int cone_max_samples = 16;     // in-circles marched per cone
    float cone_level_bias = 1.0f;  // added to the mip level of every cone / blur_mips fetch
    ConeRemainder cone_remainder = ConeRemainder::Hit;  // what fills a cone whose weights stay below 1
    bool cone_stretch = false;  // seed 002 4.6.8: footprints stretched along the ray at grazing angles
    // Unresolved rays: the environment weighted by the share the scene leaves open (specular_occlusion pass).
    SpecularOcclusion specular_occlusion = SpecularOcclusion::Exit;

    // Denoiser of the resolved reflection (seed 003: SVGF, Schied et al. 2017); units in
    // python/ssrlab/settings.py.
    Denoise denoise = Denoise::None;
    int svgf_max_history = 32;          // frames; colour and moments blend with weight 1 / min(n, this)
    int svgf_iterations = 5;            // a-trous wavelet iterations (step 2^i pixels)
    float svgf_sigma_depth = 1.0f;      // sigma_z: depth difference over the depth gradient's prediction
    float svgf_sigma_normal = 128.0f;   // sigma_n: exponent on the normals' cosine
    float svgf_sigma_luminance = 4.0f;  // sigma_l: luminance difference in standard deviations

    // User passes (passes/user_pass.h) a render runs, by name, and their parameters by
    // "<pass>.<param>" (the declared default where absent); checked against the renderer's
    // registered passes (Renderer::check_user_settings).
    struct UserPassSettings {
        std::vector<std::string> passes;
        std::map<std::string, double> params;
    } user;

    // Rays traced per pixel: the cone and blur_mips methods trace one mirror ray.
    int traced_rays() const { return glossy == Glossy::Stochastic ? rays_per_pixel : 1; }

    int trace_width() const { return (width + downscale - 1) / downscale; }
    int trace_height() const { return (height + downscale - 1) / downscale; }

    void validate() const;  // throws std::invalid_argument naming the field
};

}  // namespace ssr
