"""Render settings: one validated object with documented units and defaults.

Every field is declared once below with its unit, range and meaning; validation, the
generated documentation (``help(ssrlab.Settings)``) and the conversion to the native
renderer all read that one declaration. An invalid value raises ``ValueError`` naming the
field, at construction and on assignment.
"""

from __future__ import annotations

import dataclasses
import difflib
import functools
import json
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from . import _core


def _setting(default, doc: str, unit: str = "", lo=None, hi=None, choices=None, group: str = "", off=None):
    """A field: `lo`..`hi` inclusive range, or one of `choices`; `off` is an extra allowed
    value outside the range that switches the feature off."""
    return field(
        default=default,
        metadata={"doc": doc, "unit": unit, "lo": lo, "hi": hi, "choices": choices, "group": group, "off": off},
    )


@dataclass
class Settings:
    # -- image -----------------------------------------------------------------------------
    width: int = _setting(640, "image width", "pixels", 1, 16384, group="image")
    height: int = _setting(360, "image height", "pixels", 1, 16384, group="image")

    # -- deep G-buffer (seed 000, 1.5.1 and 2.2) ---------------------------------------------
    layers: int = _setting(
        1, "depth-peeled G-buffer layers; layer i+1 holds the nearest surface strictly behind layer i",
        "layers", 1, 16, group="deep G-buffer")
    backface_culling: bool = _setting(
        False, "cull back faces; off as in the thesis, so back faces populate deeper layers",
        group="deep G-buffer")
    depth_mode: str = _setting(
        "standard", "depth convention: 'standard' (GL, near->0, far->1) or 'reversed_z' (float, near->1, far->0)",
        choices=("standard", "reversed_z"), group="deep G-buffer")
    deep_gbuffer: str = _setting(
        "auto", "how the layered G-buffer is built: 'peel' (depth peeling, one geometry pass per layer, seed 000 "
        "1.5.1), 'lists' (one geometry pass appending every fragment to per-pixel linked lists, Yang et al. "
        "2010, then a selection of each pixel's `layers` nearest depths: the same layers as 'peel' bit for "
        "bit, equal depths included) or 'auto' (the exact method this device builds faster: measured by the "
        "Renderer once per scene, size and layer count, Renderer.deep_gbuffer_measurements; one layer is "
        "peeled; Frame.settings holds the one the frame ran with)", choices=("auto", "peel", "lists"), group="deep G-buffer")
    deep_gbuffer_budget: int = _setting(
        0, "deep_gbuffer 'lists': the most memory its fragment store may take (64 bytes a fragment; 0: the "
        "device's largest storage buffer; more than that is a ValueError); a frame with more fragments is never "
        "truncated: it is built by peeling instead (Frame.stats['deep_gbuffer_fell_back'])",
        "MiB", 1, 1 << 20, group="deep G-buffer", off=0)

    # -- direct lighting -------------------------------------------------------------------------
    shadow_map_size: int = _setting(
        2048, "shadow-map resolution of the shadow-casting directional light; 0 turns shadows off",
        "texels", 16, 16384, group="lighting", off=0)
    shadow_normal_offset: float = _setting(
        1.5, "receiver offset along its normal against shadow acne", "shadow texels", 0.0, 64.0, group="lighting")
    shadow_pcf_radius: int = _setting(
        1, "percentage-closer filtering kernel radius r: (2r+1)^2 hardware-filtered taps", "taps", 0, 4,
        group="lighting")

    # -- reflection rays (seed 000, 2.3; seed 002, 4.4) ---------------------------------------------
    method: str = _setting(
        "linear", "tracer: 'linear' (McGuire-Mara DDA, thesis 2.3.1), 'hiz' (min-max Hi-Z traversal, seed 002), "
        "'bvh' (every ray traced against the scene's triangles and shaded by the G-buffer's shading code with "
        "the frame's shadow map, seen from the camera: seed 003's ray-traced reflections) "
        "or 'off' (no reflections)", choices=("linear", "hiz", "bvh", "off"), group="rays")
    fallback: str = _setting(
        "environment", "what a ray screen space cannot resolve (a miss: it left the screen, reached max_steps or "
        "ran behind every layer; or a faded hit) brings: 'environment' (the environment along it), 'bvh' (the "
        "ray retraced from its origin against the scene's triangles and shaded as method 'bvh' shades; faded "
        "hits fade toward it; thesis 4.3, seed 004), 'probes' (seed 004's local cube maps: the nearest "
        "reflection probe, box-projected on the scene bounds, refined by its distances and pre-filtered by "
        "roughness, then the "
        "environment; probes at Scene.probes or placed by probe_grid, captured once per scene and probe set) "
        "or 'none' (nothing: black). Ignored by method 'bvh'",
        choices=("none", "environment", "bvh", "probes"), group="rays")
    fallback_confidence: bool = _setting(
        True, "with fallback 'bvh': screen-space hits that fail the confidence test (the hit surface faces the "
        "ray, the hit lies within 2 pixel footprints of the ray, its object is its 4 neighbours'; "
        "shaders/lib/screen_confidence.glsl) are retraced by the BVH too (fallback 'probes' keeps them: a "
        "probe is no better than a doubtful hit)", group="rays")
    bvh_shadows: str = _setting(
        "map", "how the BVH passes (method 'bvh', fallback 'bvh', the probes' capture) shadow the surfaces they "
        "shade: 'map' (the frame's shadow map, as the lit G-buffer) or 'traced' (a shadow ray toward the light "
        "the frame shadows, the reference's shadows='traced')", choices=("map", "traced"), group="rays")
    probe_size: int = _setting(
        128, "fallback 'probes': face size of each probe's cube map (lit colour + distance, with a mip chain)",
        "texels", 8, 1024, group="rays")
    probe_grid: int = _setting(
        1, "fallback 'probes' on a scene without Scene.probes: g x g x g probes at the cell centres of the "
        "scene bounds (1: one probe at the bounds' centre)", "probes per axis", 1, 4, group="rays")
    rays_per_pixel: int = _setting(1, "reflection rays per reflective pixel", "rays", 1, 32, group="rays")
    sampling: str = _setting(
        "ggx", "ray directions: 'mirror'; 'ggx' (the thesis's theta/phi GGX normal sampling, 2.3.2); "
        "'vndf' (GGX visible normals, Heitz 2018); 'ggx_thesis_literal' (the thesis's vector "
        "(.., 1 - cos theta) added to the normal: biased, kept to measure it)",
        choices=("mirror", "ggx", "vndf", "ggx_thesis_literal"), group="rays")
    noise: str = _setting(
        "pcg", "random numbers: 'pcg' (PCG hash) or 'thesis_hash' (fract(sin(..)*43758.5453), thesis 2.3.4)",
        choices=("pcg", "thesis_hash"), group="rays")
    hammersley: bool = _setting(True, "add a Hammersley point to each ray's random numbers (thesis 2.3.4)",
                                group="rays")
    seed: int = _setting(0, "random seed of ray directions and jitter", "", 0, 2**31 - 1, group="rays")
    max_distance: float = _setting(1000.0, "view-space length of a ray", "world units", 1e-3, 1e7, group="rays")
    origin_bias: float = _setting(
        0.002, "ray origin offset along the surface normal, times the origin's view depth", "x depth", 0.0, 1.0,
        group="rays")
    roughness_cutoff: float = _setting(
        1.0, "pixels rougher than this trace no rays and reflect the environment (seed 003's threshold)",
        "perceptual roughness", 0.0, 1.0, group="rays")
    skip: bool | str = _setting(
        "auto", "True: the classify pass lists the trace pixels that need rays (reflective, below "
        "roughness_cutoff, facing the camera) and the trace pass runs by indirect dispatch over that list "
        "only (FidelityFX SSSR's classification); lighting shades only the layers the peeling "
        "found non-empty and clears the others as uncovered. False: every trace pixel and ray, every "
        "allocated layer. 'auto': True on llvmpipe, False on a GPU, the faster of the two on each (an H100 "
        "ran skip off faster at every reflective share, 0-100 %: README, GPU). The images agree either way; "
        "Frame.settings holds the value the frame ran with", choices=("auto",), group="rays")
    classify_facing: float = _setting(
        0.0, "skip=True: pixels whose normal faces the camera by less than this (n.v, the cosine of the "
        "viewing angle) get no rays (seed 004's early out by angle); 0 keeps every ray the trace would draw",
        "cosine", 0.0, 1.0, group="rays")
    adaptive_rays: bool = _setting(
        False, "rays per pixel follow the perceptual roughness within rays_per_pixel: ceil(rays_per_pixel * "
        "roughness), at least 1, so a mirror traces one ray (seed 000 4.4's future work); the resolve "
        "averages each pixel's rays with the weights they were drawn with", group="rays")
    variance_rays: bool = _setting(
        False, "with adaptive_rays: a variance_rays pass measures how much the first pass's rays disagree over "
        "each trace pixel's 3x3 neighbourhood and a second trace adds the rays adaptive_rays left out (up to "
        "rays_per_pixel) where they disagree by variance_threshold or more (FidelityFX SSSR's variance-guided "
        "extra rays); the resolve averages them with the weights they were drawn with", group="rays")
    variance_threshold: float = _setting(
        0.25, "variance_rays: relative standard deviation (std / mean) of the neighbourhood's ray luminance "
        "from which a pixel gets the extra rays; 0: every pixel with fewer than rays_per_pixel rays",
        "", 0.0, 1e3, group="rays")

    # -- hit test ------------------------------------------------------------------------------------------
    thickness: float = _setting(
        0.2, "how far behind its depth every G-buffer sample counts as solid; a ray hits layer k where it "
        "lies within [depth_k, depth_k + thickness]", "world units", 0.0, 1e6, group="hit test")
    thickness_mode: str = _setting(
        "constant", "'constant', or 'ray_step' (thesis 2.3.1: max(thickness, thickness_scale * the ray's depth "
        "change over one step), linear tracer only)", choices=("constant", "ray_step"), group="hit test")
    thickness_scale: float = _setting(1.0, "factor of the ray's depth step in thickness_mode='ray_step'", "",
                                      0.0, 1e3, group="hit test")

    # -- linear tracer -------------------------------------------------------------------------------------
    stride: float = _setting(1.0, "pixels per step along the ray's major screen axis", "pixels", 1.0, 64.0,
                             group="linear tracer")
    jitter: float = _setting(
        1.0, "per-pixel start offset of the sampled pixels: jitter * a random number * (stride - 1) pixels "
        "(McGuire & Mara); no effect at stride 1", "", 0.0, 1.0, group="linear tracer")
    max_steps: int = _setting(
        512, "linear: steps per ray; hiz: traversal iterations per ray", "steps", 1, 100000, group="linear tracer")
    refine_steps: int = _setting(
        0, "binary-search steps after a hit, between the previous and the hit step (seed 001 3.4, seed 002 "
        "Fig. 4.5)", "steps", 0, 16, group="linear tracer")

    # -- Hi-Z tracer ---------------------------------------------------------------------------------------
    hiz_start_level: int = _setting(1, "pyramid level the traversal starts at (seed 002 demo: 2)", "level", 0, 15,
                                    group="hi-z tracer")
    hiz_stop_level: int = _setting(
        0, "level at which an overlap counts as a hit; 0 is exact, higher is coarser and faster", "level", 0, 15,
        group="hi-z tracer")
    hiz_max_level: int = _setting(12, "coarsest level the traversal climbs to", "level", 0, 15, group="hi-z tracer")
    hiz_linear_steps: int = _setting(
        0, "level-0 cell steps before the hierarchical traversal (seed 002, 4.7.1)", "cells", 0, 64,
        group="hi-z tracer")
    hiz_use_max: bool = _setting(
        True, "use the max pyramid to travel behind surfaces (seed 002, 4.6.6); False: min-only Hi-Z",
        group="hi-z tracer")
    hiz_crossing_offset: float = _setting(
        0.01, "how far past a cell boundary a crossing lands (seed 002's epsilon)", "pixels", 1e-5, 0.5,
        group="hi-z tracer")

    # -- resolve (seed 000, 2.4 and 2.6) -----------------------------------------------------------------
    downscale: int = _setting(1, "rays are traced at 1/downscale resolution (thesis 2.6): 1, 2 or 4", "x",
                              1, 4, choices=None, group="resolve")
    reuse_radius: int = _setting(
        1, "neighbour rays each pixel reuses: 0 none, 1 the thesis's 3x3, 2 a 5x5", "trace pixels", 0, 2,
        group="resolve")
    reuse_weighting: str = _setting(
        "brdf", "'thesis' (every ray keeps its own weight) or 'brdf' (a neighbour's ray weighted by this "
        "pixel's BRDF over its pdf, Stachowiak 2015)", choices=("thesis", "brdf"), group="resolve")
    edge_aware: bool = _setting(
        True, "weight reused and upsampled rays by depth and normal similarity, so reflections do not bleed "
        "across silhouettes", group="resolve")
    edge_depth_sigma: float = _setting(0.05, "relative depth difference scale of edge-aware weights", "",
                                       1e-6, 1e3, group="resolve")
    edge_normal_power: float = _setting(16.0, "exponent on the normals' cosine in edge-aware weights", "",
                                        0.0, 1024.0, group="resolve")

    # -- fades and composite (seed 002, 4.6.1; seed 000, 2.4.2) ---------------------------------------
    fade_border: float = _setting(
        0.05, "hits within this share of the image's smaller side from its border fade to the environment",
        "fraction", 0.0, 0.5, group="fades")
    fade_camera_start: float = _setting(
        0.5, "rays toward the camera fade from this cosine between ray and direction to the camera...", "cos",
        -1.0, 1.0, group="fades")
    fade_camera_end: float = _setting(0.9, "...to fully faded at this one (end <= start: no fade)", "cos",
                                      -1.0, 1.0, group="fades")
    fade_distance_start: float = _setting(
        0.0, "hits farther than this from the ray origin start to fade (0: no distance fade)", "world units",
        0.0, 1e7, group="fades")
    fade_distance_end: float = _setting(0.0, "...and are fully faded at this distance", "world units", 0.0, 1e7,
                                        group="fades")
    composite: str = _setting(
        "linear", "'linear': c = r c_r + (1 - r) c_d (thesis 2.4.2); 'pbr': c = c_d + k E c_r, E = F0 A + B the "
        "GGX directional albedo (split-sum table integrated by the tracers' sampler), k = r (1 for 'auto' "
        "materials): the physically based image", choices=("linear", "pbr"), group="fades")

    # -- frames in time (seed 002, 4.6.5 and 4.7.4; seed 000, 4.4): Renderer.render_sequence ------
    temporal_reflections: bool = _setting(
        False, "accumulate the resolved reflection over a sequence's frames: the reproject and temporal "
        "passes; the composite uses the accumulation (frame.reflection). Each frame of a sequence draws new "
        "rays (seed + frame index)", group="temporal")
    temporal_max_history: int = _setting(
        32, "history length cap n_max: the current frame weighs 1/n with n = min(frames of valid history + 1, "
        "n_max), i.e. the plain mean of the last frames up to n_max, then an exponential average whose history "
        "weight is 1 - 1/n_max", "frames", 1, 1024, group="temporal")
    reject_depth: float = _setting(
        0.05, "history is rejected where the previous view depth at the reprojected position differs from the "
        "point's by more than this share of it (disocclusion); 0 turns the test off", "relative", 0.0, 10.0,
        group="temporal")
    reject_normal: float = _setting(
        0.9, "history is rejected where the cosine between this and the previous normal is below this; -1 "
        "turns the test off", "cos", -1.0, 1.0, group="temporal")
    reject_offscreen: bool = _setting(
        True, "reject history whose reprojected position lies outside the previous image (False: clamp to "
        "its edge)", group="temporal")
    temporal_clamp: float = _setting(
        0.0, "neighbourhood variance clamp of the reflection history (Salvi 2016): the reprojected history is "
        "clamped to this frame's 3x3 mean +- this many standard deviations in YCoCg, which removes the ghost "
        "trails of view-dependent reflections under camera motion that depth/normal rejection cannot see; "
        "0 turns it off (a static camera converges best without it)", "sigma", 0.0, 16.0, group="temporal")
    taa: str = _setting(
        "off", "temporal anti-aliasing of the final image over a sequence (frame.color): 'thesis' (seed 000 2.5: "
        "two alternating quarter-pixel jitters, the mean of this and the previous frame, no reprojection), "
        "'clamped' (Halton(2,3) jitter, reprojected history clamped to the YCoCg min/max of the 3x3 "
        "neighbourhood) or 'off'", choices=("off", "thesis", "clamped"), group="temporal")
    taa_history_weight: float = _setting(
        0.9, "taa='clamped': weight of the clamped history in the blend (the current frame gets the rest)", "",
        0.0, 0.99, group="temporal")
    bounces: str = _setting(
        "single", "'single': rays bring the lit colour of what they hit; 'history' (seed 002, 4.6.4): rays that "
        "hit layer 0 bring the previous frame's final colour at the hit's reprojected position (this frame's "
        "lit colour where that history is rejected), so mirrors facing mirrors gain a bounce per frame",
        choices=("single", "history"), group="temporal")
    temporal_ray_reuse: bool = _setting(
        False, "ray-result reuse over time (seed 000, 4.4): the resolve also takes the previous frame's rays of "
        "the reprojected pixel's reuse neighbourhood as extra neighbours (their hits shaded with the previous "
        "frame's lit colour), doubling the rays each pixel averages; where the reprojection rejects the "
        "history (Settings.reject_*), only this frame's rays count", group="temporal")

    # -- glossy reflections (seed 002, 4.4.2-4.4.5; seed 004) ------------------------------
    glossy: str = _setting(
        "stochastic", "how rough surfaces blur the reflection: 'stochastic' (rays_per_pixel GGX rays drawn by "
        "`sampling`, then the resolve); 'cone' (one mirror ray per pixel traced by `method`, then a cone "
        "marched through the pre-convolved colour and pre-integrated visibility mips with the Hi-Z, seed "
        "002 4.4.5; the cone's half-angle holds ssrlab.glossy.CONE_ENERGY of the GGX lobe); 'blur_mips' "
        "(one mirror ray, the pre-convolved colour at a mip level from roughness and hit distance, seed "
        "004). cone and blur_mips ignore rays_per_pixel, sampling and the resolve",
        choices=("stochastic", "cone", "blur_mips"), group="glossy")
    cone_max_samples: int = _setting(
        16, "most in-circles of the screen-space isosceles triangle a cone samples (seed 002, 4.4.5)", "samples",
        1, 64, group="glossy")
    cone_level_bias: float = _setting(
        1.0, "added to the mip level of every cone / blur_mips colour fetch (level = log2 of the in-circle "
        "or footprint radius in pixels, + bias); 1 measured best on hall and spheres_and_boxes at "
        "roughness 0.2 (the GGX lobe's tails blur more than its median cone)", "levels", -4.0, 4.0,
        group="glossy")
    cone_remainder: str = _setting(
        "hit", "what fills the share of a cone whose weights (visibility x sphere overlap) stay below 1: "
        "'hit' (the colour of the cone's circle at the hit, since the centre ray proved a surface there) or "
        "'environment' (seed 002 4.4.5's choice; leaks the sky into closed rooms at silhouettes)",
        choices=("hit", "environment"), group="glossy")
    cone_stretch: bool = _setting(
        False, "vertically stretched cones at grazing angles (seed 002, 4.6.8): each cone sample's footprint "
        "becomes r / sqrt(N.V) along the ray's screen direction and r sqrt(N.V) across it (at most 4:1), "
        "read as up to 4 samples along the ray at the narrow side's mip level", group="glossy")
    specular_occlusion: str = _setting(
        "exit", "what a reflection ray screen space did not resolve (a miss, or the faded share of a hit) "
        "brings with fallback 'environment' (the specular_occlusion pass; docs/occlusion.md): 'off' the "
        "environment; otherwise the environment weighted by the estimated share of the ray (of the lobe, for "
        "glossy 'cone' and 'blur_mips') the scene leaves open, the rest the ambient term of the surface that "
        "blocks it, and a faded hit that faces its ray its hit's lit colour. 'exit': what the frame knows of "
        "where the ray went: blocked where its way to the screen's edge passes behind every surface of a "
        "closed region (no background in a cell of 1/16 of the image height and its neighbours), or where it "
        "leaves the screen running into the plane of the surface at its exit pixel (the deep G-buffer's first "
        "layer at or behind it); open where it leaves into background. 'horizon': GTSO (Jimenez et al. 2016), "
        "the visibility cone of horizon-based ambient occlusion over layer 0's depth intersected with the GGX "
        "lobe. Ignored with other fallbacks and method 'bvh'. frame.stats counts unresolved_rays and "
        "occluded_misses (estimated visibility below 1/2)",
        choices=("off", "horizon", "exit"), group="glossy")

    # -- denoiser of the reflection (seed 003: SVGF, Schied et al. 2017) -------------------
    denoise: str = _setting(
        "none", "denoiser of the resolved reflection, for every method and fallback: 'svgf' (Schied et al. "
        "2017 as seed 003 uses it: the svgf_temporal pass accumulates colour and the first and second "
        "luminance moments over a sequence's frames through the reproject pass's history and rejection; "
        "svgf_variance estimates the luminance variance, spatially (7x7, depth- and normal-guided) while the "
        "history holds fewer than 4 frames; svgf_atrous filters with svgf_iterations a-trous wavelet passes "
        "guided by depth, normal and luminance variance; the composite and frame.reflection use the result). "
        "A single render() has no history: spatial variance and the wavelet passes only. Pixels whose rays "
        "are noiseless (roughness 0 or sampling 'mirror') are left as traced. 'none': no denoiser",
        choices=("none", "svgf"), group="denoiser")
    svgf_max_history: int = _setting(
        32, "svgf: history length cap n_max of the colour and moments accumulation: this frame weighs 1/n, "
        "n = min(frames of valid history + 1, n_max) (SVGF's alpha = 0.2 is n_max = 5)", "frames", 1, 1024,
        group="denoiser")
    svgf_iterations: int = _setting(
        5, "svgf: a-trous wavelet iterations; iteration i spaces its 5x5 B3-spline taps 2^i pixels apart "
        "(5: a 125-pixel footprint); its first output is the colour history of the next frame; 0: temporal "
        "accumulation only", "iterations", 0, 8, group="denoiser")
    svgf_sigma_depth: float = _setting(
        1.0, "svgf sigma_z: taps weigh exp(-|z_p - z_q| / (sigma_z |grad z . (p - q)|)), linear depth against "
        "what the depth gradient predicts over the tap's offset", "", 1e-3, 1e3, group="denoiser")
    svgf_sigma_normal: float = _setting(
        128.0, "svgf sigma_n: taps weigh max(0, n_p . n_q)^sigma_n", "", 0.0, 1024.0, group="denoiser")
    svgf_sigma_luminance: float = _setting(
        4.0, "svgf sigma_l: taps weigh exp(-|l_p - l_q| / (sigma_l sqrt(variance of l_p, 3x3 Gaussian-"
        "filtered))), the luminance difference in standard deviations of the noise", "sigma", 1e-3, 1e3,
        group="denoiser")

    # -- user passes (ssrlab.UserPass, docs/guide/your-first-technique.md) ---------------------------
    user_passes: tuple = field(default=(), metadata={
        "doc": "user passes this render runs, by name (registered with Renderer.register_pass); each takes its "
               "stage's place (a 'trace' replaces the screen-space trace, a 'reflection_filter' follows the "
               "resolve)", "unit": "", "lo": None, "hi": None, "choices": None, "group": "user passes", "off": None})
    user_params: dict = field(default_factory=dict, metadata={
        "doc": "parameters of user passes, '<pass>.<param>' -> value (absent: the declared default); a sweep or "
               "replace() may name a key directly: replace(**{'<pass>.<param>': value})", "unit": "", "lo": None,
        "hi": None, "choices": None, "group": "user passes", "off": None})

    # ---------------------------------------------------------------------------------------------
    def __post_init__(self) -> None:
        # Construction, replace() and from_dict() end here: the fields are checked one by one
        # by __setattr__, the constraints between fields here (see CONSTRAINTS).
        self.check_constraints()

    def check_constraints(self) -> None:
        """Raises ValueError naming both fields when a constraint between fields (CONSTRAINTS)
        fails. Checked when Settings is built or replaced and again before every render (single
        assignments are checked per field only, so that related fields can be set in turn)."""
        for c in CONSTRAINTS:
            c.check(self)

    def __setattr__(self, name: str, value: Any) -> None:
        # Every assignment, the dataclass __init__'s included, goes through the field's check.
        spec = _FIELDS.get(name)
        if spec is None:
            raise AttributeError(f"Settings has no field {name!r}{_suggestion(name)}; fields: {', '.join(_FIELDS)}")
        object.__setattr__(self, name, _check(spec, value))

    def replace(self, **changes) -> "Settings":
        """A copy with some fields changed (validated)."""
        changes = _user_param_keys(changes, self.user_params)
        _check_names(changes)
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> "Settings":
        _check_names(d)
        return cls(**d)

    def key(self) -> str:
        """A stable text key of every field (for caches and result rows)."""
        return json.dumps(self.to_dict(), sort_keys=True)

    def changed(self) -> dict:
        """The fields whose value differs from the default, in field order."""
        return {f.name: getattr(self, f.name) for f in fields(self) if getattr(self, f.name) != _default(f)}

    def __repr__(self) -> str:
        # Only what differs from the defaults, so that a repr stays readable and evaluates back.
        return "Settings(" + ", ".join(f"{k}={v!r}" for k, v in self.changed().items()) + ")"


    def resolved(self, device: str) -> "Settings":
        """A copy with every 'auto' value decided for `device` ('cpu': llvmpipe, 'gpu'): what a
        Renderer on that device renders with (Frame.settings)."""
        if device not in ("cpu", "gpu"):
            raise ValueError(f"device must be 'cpu' or 'gpu', got {device!r}")
        s = self.replace(skip=device == "cpu") if self.skip == "auto" else self
        # deep_gbuffer 'auto': a Renderer measures both methods per scene (Renderer.render);
        # settings resolved without a renderer and scene peel (docs/deep_gbuffer.md).
        return s.replace(deep_gbuffer=_auto_deep_gbuffer(device, s.layers)) if s.deep_gbuffer == "auto" else s

    def to_native(self, device: str = "cpu") -> "_core.RenderSettings":
        """The native renderer's settings; 'auto' values decided for `device` (see resolved())."""
        self.check_constraints()
        s = self.resolved(device)
        native = _core.RenderSettings()
        for name in _NATIVE_FIELDS:
            setattr(native, name, getattr(s, name))
        native.user_params = {k: float(v) for k, v in s.user_params.items()}
        native.validate()
        return native

    @staticmethod
    def describe() -> str:
        """A table of every field: default, unit, range and meaning."""
        lines, group = [], None
        for f in fields(Settings):
            m = f.metadata
            if m["group"] != group:
                group = m["group"]
                lines.append(f"\n[{group}]")
            rng = ""
            if m["choices"]:
                rng = " | ".join(("True", "False", *m["choices"]) if f.type == "bool | str" else m["choices"])
            elif m["lo"] is not None:
                rng = f"[{m['lo']}, {m['hi']}]" + (f" or {m['off']} (off)" if m["off"] is not None else "")
            unit = f" {m['unit']}" if m["unit"] else ""
            lines.append(f"  {f.name} = {_default(f)!r}{unit}  {rng}\n      {m['doc']}")
        from .user_pass import declared

        if declared():
            lines.append("\n[user pass parameters] (Settings.user_params keys; the passes registered in this process)")
            lines += [p.describe() for p in declared().values()]
        lines.append("\n[constraints] (between fields; checked when Settings is built or replaced, and at render)")
        for c in CONSTRAINTS:
            lines.append(f"  {c.rule}\n      {c.why}")
        lines.append("  (allowed) fade_camera_end <= fade_camera_start\n      switches the fade toward the camera off")
        return "\n".join(lines).lstrip("\n")


def _auto_deep_gbuffer(device: str, layers: int) -> str:
    """deep_gbuffer 'auto' on `device`: the exact method that builds `layers` layers faster."""
    return "peel"


def _user_param_keys(changes: dict, current: dict) -> dict:
    """Keys '<pass>.<param>' (a user pass's parameter) moved into user_params."""
    dotted = {k: v for k, v in changes.items() if isinstance(k, str) and "." in k}
    if not dotted:
        return changes
    out = {k: v for k, v in changes.items() if k not in dotted}
    out["user_params"] = {**out.get("user_params", current), **dotted}
    return out


def _default(f: dataclasses.Field) -> Any:
    return f.default_factory() if f.default is dataclasses.MISSING else f.default


def _suggestion(name: str) -> str:
    """' (did you mean 'x'?)' for the field nearest to a misspelled name, or ''."""
    close = difflib.get_close_matches(str(name), list(_FIELDS), n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def _check_names(names) -> None:
    """ValueError naming every unknown field, with the nearest field for each."""
    unknown = sorted(set(names) - set(_FIELDS), key=str)
    if unknown:
        raise ValueError("unknown Settings field(s): " + ", ".join(f"{n!r}{_suggestion(n)}" for n in unknown)
                         + f"; fields: {', '.join(_FIELDS)}")


def _check(f: dataclasses.Field, value: Any) -> Any:
    m, name, typ = f.metadata, f"Settings.{f.name}", f.type
    if f.name == "user_passes":
        if isinstance(value, str):
            value = (value,)
        if not isinstance(value, (tuple, list)) or not all(isinstance(v, str) and v for v in value):
            raise ValueError(f"{name} must be a tuple of user pass names, got {value!r}")
        if len(set(value)) != len(value):
            raise ValueError(f"{name} names a pass twice: {value!r}")
        return tuple(value)
    if f.name == "user_params":
        from .user_pass import check_params

        return check_params(value)
    if typ == "bool | str":  # True, False, or one of the named choices ('auto')
        if isinstance(value, str) and value in m["choices"]:
            return value
        if isinstance(value, np.bool_):
            value = bool(value)
        if not isinstance(value, bool):
            raise ValueError(f"{name} must be True, False or one of {', '.join(map(repr, m['choices']))}, "
                             f"got {value!r}")
        return value
    if typ in ("bool", bool):
        if isinstance(value, np.bool_):
            value = bool(value)
        if not isinstance(value, bool):
            raise ValueError(f"{name} must be True or False, got {value!r}")
        return value
    if typ in ("int", int):
        if isinstance(value, bool):
            raise ValueError(f"{name} must be an integer, got {value!r}")
        if isinstance(value, (int, np.integer)) or (isinstance(value, float) and value.is_integer()):
            value = int(value)
        else:
            raise ValueError(f"{name} must be an integer, got {value!r}")
    elif typ in ("float", float):
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise ValueError(f"{name} must be a number, got {value!r}")
        value = float(value)
        if value != value or value in (float("inf"), float("-inf")):
            raise ValueError(f"{name} must be finite, got {value!r}")
    elif typ in ("str", str):
        if not isinstance(value, str):
            raise ValueError(f"{name} must be a string, got {value!r}")
        if m["choices"] and value not in m["choices"]:
            raise ValueError(f"{name} must be one of {', '.join(map(repr, m['choices']))}, got {value!r}")
        return value
    if f.name == "downscale" and value not in (1, 2, 4):
        raise ValueError(f"{name} must be 1, 2 or 4, got {value!r}")
    lo, hi = m["lo"], m["hi"]
    if m["off"] is not None and value == m["off"]:
        return value
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        unit = f" {m['unit']}" if m["unit"] else ""
        off = f" (or {m['off']}: off)" if m["off"] is not None else ""
        raise ValueError(f"{name} must be in [{lo}, {hi}]{unit}{off}, got {value!r}")
    return value


@dataclass(frozen=True)
class Constraint:
    """A rule between fields: `rule` as users read it, `ok(settings)` the test, `why` what
    breaks otherwise."""
    fields: tuple
    rule: str
    ok: Any
    why: str

    def check(self, s: "Settings") -> None:
        if not self.ok(s):
            got = ", ".join(f"{n}={getattr(s, n)!r}" for n in self.fields)
            raise ValueError(f"Settings: {self.rule} is violated ({got}); {self.why}")


# Every cross-field rule, also enforced (where a pass depends on it) by the native
# RenderSettings::validate(). Rules whose violation the renderer would silently ignore (a
# clamped level, a fade that never happens) are errors too, so that a setting always acts.
CONSTRAINTS = (
    Constraint(("method", "glossy"), "glossy == 'stochastic' when method == 'bvh'",
               lambda s: s.method != "bvh" or s.glossy == "stochastic",
               "the BVH's radiance reaches the image through the resolve; cone and blur_mips read screen-space hits"),
    Constraint(("method", "fallback", "temporal_ray_reuse"),
               "method != 'bvh' and fallback not in ('bvh', 'probes') when temporal_ray_reuse",
               lambda s: not s.temporal_ray_reuse or (s.method != "bvh" and s.fallback not in ("bvh", "probes")),
               "the previous frame's rays would bring their screen-space hits only, not the BVH's radiance"),
    Constraint(("denoise", "temporal_reflections"), "temporal_reflections is off when denoise == 'svgf'",
               lambda s: s.denoise != "svgf" or not s.temporal_reflections,
               "SVGF accumulates its own history; a second accumulation after it would only add lag"),
    Constraint(("fallback", "glossy"), "glossy == 'stochastic' when fallback in ('bvh', 'probes')",
               lambda s: s.fallback not in ("bvh", "probes") or s.glossy == "stochastic",
               "the BVH's radiance reaches the image through the resolve; cone and blur_mips read screen-space hits"),
    Constraint(("variance_rays", "adaptive_rays", "method", "glossy"),
               "adaptive_rays, method in ('linear', 'hiz') and glossy == 'stochastic' when variance_rays",
               lambda s: not s.variance_rays or (s.adaptive_rays and s.method in ("linear", "hiz")
                                                 and s.glossy == "stochastic"),
               "the second pass adds the rays adaptive_rays left out, for the screen-space tracers' stochastic rays"),
    Constraint(("hiz_stop_level", "hiz_max_level"), "hiz_stop_level <= hiz_max_level",
               lambda s: s.hiz_stop_level <= s.hiz_max_level,
               "the traversal never descends below the stop level, so it cannot stop above the coarsest level"),
    Constraint(("hiz_start_level", "hiz_max_level"), "hiz_start_level <= hiz_max_level",
               lambda s: s.hiz_start_level <= s.hiz_max_level,
               "a start level above the coarsest level would be clamped to it without a word"),
    Constraint(("fade_distance_start", "fade_distance_end"),
               "fade_distance_end > fade_distance_start when fade_distance_start > 0",
               lambda s: s.fade_distance_start == 0.0 or s.fade_distance_end > s.fade_distance_start,
               "the distance fade runs from start to end; with end <= start it would never happen"),
    Constraint(("fade_distance_start", "fade_distance_end"),
               "fade_distance_end == 0 when fade_distance_start == 0",
               lambda s: s.fade_distance_start > 0.0 or s.fade_distance_end == 0.0,
               "fade_distance_start = 0 switches the distance fade off, so an end distance would be ignored; "
               "set fade_distance_start > 0 to fade"),
)
# Documented, not an error: fade_camera_end <= fade_camera_start switches the camera fade off.

_FIELDS = {f.name: f for f in fields(Settings)}

_dataclass_init = Settings.__init__


@functools.wraps(_dataclass_init)
def _init(self, *args, **kwargs):
    kwargs = _user_param_keys(kwargs, {})
    _check_names(kwargs)  # a misspelled keyword names the nearest field, not just "unexpected keyword"
    _dataclass_init(self, *args, **kwargs)


Settings.__init__ = _init
_NATIVE_FIELDS = [n for n in _FIELDS if hasattr(_core.RenderSettings(), n)]


def _document_native_settings() -> None:
    """The native RenderSettings mirrors these fields: its properties get their documentation
    from the one declaration above (unless the bindings give one)."""
    for name in _NATIVE_FIELDS:
        prop = vars(_core.RenderSettings).get(name)
        if isinstance(prop, property) and not (prop.__doc__ or "").strip():
            m = _FIELDS[name].metadata
            unit = f" [{m['unit']}]" if m["unit"] else ""
            prop.__doc__ = f"ssrlab.Settings.{name}{unit}: {m['doc']}"


_document_native_settings()

Settings.__doc__ = "Render settings (every field validated; units in brackets).\n\n" + Settings.describe()
