"""A rendered frame: its textures on the GPU until a property reads them, its timings, statistics
and references (Renderer.render returns one)."""

from __future__ import annotations

import functools
import math
import weakref
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from . import _core
from .io import srgb8_thresholds
from .settings import Settings
from .frame_views import ChannelView, GBuffer, RayResults, Reprojection


class FrameStats(Mapping):
    """Frame.stats: exact work counts, read like a dict. The counts the trace passes keep no
    counter for (TRACE_SUMS) are summed from the frame's rays.sample the first time one of them
    is read, not before: reading the others reads nothing back from the GPU."""

    def __init__(self, counts: dict[str, int], frame: "Frame | None" = None):
        self._counts = counts
        # A weak reference: a kept stats object does not keep the frame's textures alive.
        self._frame = weakref.ref(frame) if frame is not None else None

    def _sums(self) -> dict[str, int]:
        frame = self._frame() if self._frame is not None else None
        if frame is not None and frame._trace_sum_cache is not None:
            return frame._trace_sum_cache
        if frame is None or frame.released:
            raise KeyError("rays_traced and depth_fetches are summed from the frame's rays.sample when first read, "
                           "and this frame was released (or dropped) before that: read them from frame.stats "
                           "before releasing the frame")
        return frame._trace_sums(self._counts)

    def __getitem__(self, key: str) -> int:
        if key in self._counts:
            return self._counts[key]
        if self._frame is not None and key in TRACE_SUMS:
            return self._sums()[key]
        raise KeyError(key)

    def __contains__(self, key: object) -> bool:
        return key in self._counts or (self._frame is not None and key in TRACE_SUMS)

    def __iter__(self):
        yield from self._counts
        if self._frame is not None:
            yield from TRACE_SUMS

    def __len__(self) -> int:
        return len(self._counts) + (len(TRACE_SUMS) if self._frame is not None else 0)

    def __repr__(self) -> str:
        try:
            return repr(dict(self))
        except KeyError:
            return repr(self._counts)[:-1] + ", (rays_traced, depth_fetches: not read before the release)}"


# Counts the trace passes keep no counter for (an atomic per ray, which llvmpipe runs lane by
# lane, is a visible share of the Hi-Z trace there): Frame.stats sums them from the rays the
# trace wrote, when first read.
TRACE_SUMS = ("rays_traced", "depth_fetches")


class Frame:
    """One rendered frame. Image properties read from the GPU on first access.

    time: the scene time it showed, seconds (render_sequence's `times`), or None."""

    time: float | None = None

    def __init__(self, native: _core.Frame, settings: Settings, renderer=None, scene=None):
        self._native = native
        self.settings = settings
        self._renderer = renderer
        self._scene = scene
        self._cache: dict[str, np.ndarray] = {}
        self._trace_sum_cache: dict[str, int] | None = None
        # Whether a tracer ran: every tracer declares the ray textures (kept past release()).
        self.traced = "rays.hit" in native.texture_names
        # Results computed into textures a later call overwrites (ssrlab.reference._FrameResult).
        self._results: "weakref.WeakSet" = weakref.WeakSet()

    # -- lifetime -------------------------------------------------------------------------------
    def release(self) -> None:
        """Frees this frame's textures now (and its cached arrays); later reads raise
        ValueError. Scratch shared with other frames is not the frame's to free. Idempotent."""
        self._cache.clear()
        self.__dict__.pop("gbuffer", None)
        self.__dict__.pop("rays", None)
        self._native.release()

    @property
    def released(self) -> bool:
        return bool(self._native.released)

    @property
    def gpu_bytes(self) -> int:
        """Bytes of the GPU textures this frame holds (0 once released)."""
        return int(self._native.gpu_bytes)

    def __enter__(self) -> "Frame":
        return self

    def __exit__(self, *exc) -> None:
        self.release()

    def _check_live(self, what: str) -> None:
        if self._native.released:
            raise ValueError(f"cannot read {what}: this frame was released (Frame.release() or the end of its "
                             "with block); read what you need before releasing it")

    # -- metadata -------------------------------------------------------------------------------
    @property
    def timings(self) -> dict[str, float]:
        """GPU milliseconds per pass (GL timestamp queries); parts such as
        ``depth_peel.layer0`` are listed beside their pass, ``total`` sums the passes."""
        return dict(self._native.timings)

    @property
    def warmup_runs(self) -> int:
        """Untimed runs of the chain before the timed one: 1 when this variant (passes, texture
        sizes, defines, scene) was new to the renderer. Timings never include compilation or
        first-use costs."""
        return self._native.warmup_runs

    @property
    def wall_ms(self) -> float:
        """CPU milliseconds of the render call, until the GPU finished."""
        return self._native.wall_ms

    @property
    def passes(self) -> list[str]:
        return list(self._native.passes)

    @property
    def stats(self) -> FrameStats:
        """Exact work counts read back from the GPU: passes_run; where a trace ran,
        rays_traced (rays generated, weight > 0) and depth_fetches (the trace's fetches, summed);
        with Settings.skip the classify pass's classify_regions (the 32x32 regions holding a
        reflective surface, where it runs) and pixels_classified (trace pixels examined there),
        pixels_traced (trace pixels in the ray list) and trace_groups (indirect groups);
        layers_used (layers holding a surface somewhere: with skip, the Hi-Z build, the trace's
        layer walk, pre-convolution and pre-integration work on these only), layers_lit,
        with skip tiles_lit (the 8x8 covered tiles the lighting shaded),
        hiz_layers_built; with Settings.variance_rays, variance_pixels (pixels given extra
        rays), extra_rays and extra_depth_fetches (the second trace's); with skip and the
        stochastic resolve, the resolve's list: resolve_pixels (receiving pixels, own-rays
        resolve) or resolve_tiles (16x16 tiles holding a receiver), resolve_groups (its indirect
        groups) and environment_pixels (reflective pixels rougher than the cutoff, given the
        environment by the classify pass); with the specular_occlusion pass (Settings.specular_occlusion),
        unresolved_rays (rays it estimated for: misses and faded hits) and occluded_misses (those whose
        estimated visibility is below 1/2). rays_traced and depth_fetches are summed from
        rays.sample (its weight and fetch channels, less the second trace's extra_*) when one of
        them is first read (a read-back; the trace keeps no counter): read them before
        Frame.release(). With Settings.deep_gbuffer 'lists' (or 'visibility_lists'):
        deep_gbuffer_method (how the layers were built: 'lists' ('visibility_lists'), or 'peel'
        ('visibility') where the lists fell back, and 'visibility' where 'visibility_lists' builds
        one layer, which the depth test keeps without a list), deep_gbuffer_fragments (the frame's fragments),
        deep_gbuffer_bytes (the lists' buffers), deep_gbuffer_redone (1: the fragment store was
        too small and the geometry pass ran again with one that fits) and deep_gbuffer_fell_back (1:
        the fragments exceeded Settings.deep_gbuffer_budget and the layers were peeled); with
        'visibility_lists', deep_gbuffer_samples_listed (1: the selection listed every kept sample
        for the attribute pass, on the CPU device, with more than one layer and no textured
        material); with either visibility construction, gbuffer_attributes_triangle_records (the
        triangles whose shared attributes were computed once for all their samples; 0 where the
        frame has fewer than 4 texels a triangle and each sample read its own)."""
        counts = {k: int(v) for k, v in self._native.stats.items()}
        # How the deep G-buffer was built (Settings.deep_gbuffer): 'lists' or 'peel' (also where
        # 'lists' fell back to peeling: deep_gbuffer_fell_back 1).
        if "deep_gbuffer_lists" in counts:
            lists = counts.pop("deep_gbuffer_lists")
            if self.settings.deep_gbuffer == "visibility_lists":
                counts["deep_gbuffer_method"] = "visibility_lists" if lists else "visibility"
            else:
                counts["deep_gbuffer_method"] = "lists" if lists else "peel"
        return FrameStats(counts, self if self.traced else None)

    def _trace_sums(self, counts: dict[str, int]) -> dict[str, int]:
        """rays_traced and depth_fetches of the frame's (first) trace, from rays.sample: rays of
        weight > 0 and their fetch counts, as the trace wrote them, less the second trace's."""
        if self._trace_sum_cache is None:
            sample = self.read("rays.sample")
            self._trace_sum_cache = {
                "rays_traced": int(np.count_nonzero(sample[..., 0] > 0.0)) - counts.get("extra_rays", 0),
                "depth_fetches": int(sample[..., 2].astype(np.float64).sum()) - counts.get("extra_depth_fetches", 0),
            }
        return self._trace_sum_cache

    @property
    def layer_samples(self) -> list[int]:
        """Samples each G-buffer layer's geometry wrote (0: an empty layer, whose draws and
        every deeper layer's were skipped on the GPU)."""
        return list(self._native.layer_samples)

    @property
    def camera(self) -> _core.Camera:
        return self._native.camera

    @property
    def view_matrix(self) -> np.ndarray:
        return np.asarray(self._native.view_matrix)

    @property
    def projection_matrix(self) -> np.ndarray:
        return np.asarray(self._native.projection_matrix)

    @property
    def texture_names(self) -> list[str]:
        return list(self._native.texture_names)

    @functools.cached_property
    def channels(self) -> list[dict]:
        """What the channels of the frame's textures mean, as the passes that wrote them declared:
        one dict per channel (texture, view, name, first, count, decode, doc). GBuffer, RayResults
        and Reprojection are made from these."""
        return list(self._native.channels)

    # -- images -------------------------------------------------------------------------------
    def read(self, name: str, level: int = 0, *, cache: bool = True) -> np.ndarray:
        """Every layer of a texture as float32 (layers, height, width, 4), cached and read-only
        (copy it to change it: ``frame.read(name).copy()``). cache=False copies the texture from
        the GPU again into a new array and keeps nothing (what a benchmark of the readback times)."""
        self._check_live(repr(name))
        key = f"{name}@{level}"
        if key not in self._cache or not cache:
            data = self._native.read(name, level)
            if not cache:
                return data
            # Read-only: every property and result shares this one copy, so an in-place change by
            # one reader would silently change what every other reader sees.
            data.flags.writeable = False
            self._cache[key] = data
        return self._cache[key]

    @property
    def color(self) -> np.ndarray:
        """The final image: linear radiance, float32 (height, width, 3); with Settings.taa, the
        anti-aliased image (this frame's own: read("color"))."""
        if "color.taa" in self.texture_names:
            return self.read("color.taa")[0, :, :, :3]
        return self.read("color")[0, :, :, :3]

    def srgb8(self, exposure: float = 1.0) -> np.ndarray:
        """The colour (Frame.color's texture) as it is displayed: uint8 (height, width, 3), the
        sRGB codes of exposure times the linear radiance, clamped. Encoded on the device and read
        back as 3 bytes a pixel instead of the colour's 16; equal, code for code, to
        ssrlab.display.to_bytes(ssrlab.display.srgb(frame.color, exposure))."""
        self._check_live("the colour")
        e = float(exposure)
        if not math.isfinite(e):
            raise ValueError(f"Frame.srgb8: exposure must be a finite number, got {exposure!r}")
        name = "color.taa" if "color.taa" in self.texture_names else "color"
        return self._native.display_bytes(name, e, srgb8_thresholds())

    @property
    def reflection(self) -> np.ndarray:
        """The resolved reflection colour c_r the composite used, float32 (height, width, 3); 0 where
        a pixel does not reflect (or nothing was traced). With temporal_reflections, the accumulation
        over the sequence's frames; with denoise="svgf", the denoised reflection (this frame's own, as
        resolved: read("reflection"))."""
        self._check_live("the reflection")
        if "reflection.denoised" in self.texture_names:
            return self.read("reflection.denoised")[0, :, :, :3]
        if "reflection.temporal" in self.texture_names:
            return self.read("reflection.temporal")[0, :, :, :3]
        if "reflection" not in self.texture_names:
            return np.zeros((self.settings.height, self.settings.width, 3), np.float32)
        return self.read("reflection")[0, :, :, :3]

    @functools.cached_property
    def reprojection(self) -> "Reprojection":
        """Each pixel's position in the previous frame of its sequence (the reproject pass)."""
        if "reprojection" not in self.texture_names:
            raise ValueError("this frame has no reprojection (Settings.temporal_reflections is off)")
        return Reprojection(self)

    @functools.cached_property
    def reflection_reprojection(self) -> "Reprojection":
        """Each pixel's reflection's position in the previous frame of its sequence, by the motion
        of what it reflects (the reproject_reflection pass, Settings.reflection_reprojection="hit"):
        what the reflection's temporal passes read then."""
        if "reprojection.reflection" not in self.texture_names:
            raise ValueError("this frame has no reflection reprojection (it runs with "
                             "Settings.reflection_reprojection='hit' and temporal_reflections or denoise='svgf')")
        return Reprojection(self, "reprojection.reflection")

    @functools.cached_property
    def gbuffer(self) -> "GBuffer":
        return GBuffer(self)

    def view(self, name: str) -> "ChannelView":
        """The channels that the frame's passes declared under view `name` (a user pass's own, or
        "gbuffer", "rays", "reprojection"), each an attribute: ``frame.view("luma").luminance``."""
        views = sorted({c["view"] for c in self.channels})
        if name not in views:
            raise ValueError(f"Frame.view: this frame has no view {name!r} (its passes declare: {', '.join(views)})")
        known = {"gbuffer": GBuffer, "rays": RayResults, "reprojection": Reprojection}
        return known[name](self) if name in known else ChannelView(self, view=name)

    @functools.cached_property
    def rays(self) -> "RayResults":
        """Per-ray results of the trace pass (raises if the frame traced no rays)."""
        self._check_live("the rays")
        if "rays.hit" not in self.texture_names:
            raise ValueError("this frame traced no rays (method='off', or no surface has reflectivity > 0)")
        return RayResults(self)

    # Where a ray's reflection came from: Frame.ray_sources' codes.
    RAY_SOURCES = ("none", "screen", "bvh", "probes", "environment")

    def ray_sources(self) -> np.ndarray:
        """(rays, h, w) int8: where each ray's reflection came from, an index into RAY_SOURCES:
        0 no ray (or, with fallback 'none', a ray nothing resolved), 1 a screen-space hit at full
        strength, 2 the BVH's hit, 3 a reflection probe's surface, 4 the environment."""
        self._check_live("the ray sources")
        if "rays.hit" not in self.texture_names:
            raise ValueError("this frame traced no rays (method='off', or no surface has reflectivity > 0)")
        smp = self.read("rays.sample")
        hit = self.read("rays.hit")
        traced = (smp[..., 3] > 0.5) & (smp[..., 0] > 0.0)
        screen = traced & (hit[..., 2] > 0.5) & (hit[..., 3] >= 1.0)
        unresolved = traced & ~screen
        if "rays.radiance" in self.texture_names:
            found = unresolved & (self.read("rays.radiance")[..., 3] >= 0.0)
        else:
            found = np.zeros_like(traced)
        probes = self.settings.method != "bvh" and self.settings.fallback == "probes"
        none = self.settings.method != "bvh" and self.settings.fallback == "none"
        codes = np.zeros(traced.shape, np.int8)
        codes[screen] = 1
        codes[found] = 3 if probes else 2
        codes[unresolved & ~found] = 0 if none else 4
        return codes

    @property
    def fallback_stats(self) -> dict:
        """Where this frame's rays were resolved, as shares of the rays traced:
        'screen' (a screen-space hit at full strength), 'bvh' (traced against the triangles and
        hit one: method 'bvh', or fallback 'bvh' retracing a miss or a faded hit), 'probes'
        (fallback 'probes': a reflection probe's surface), 'environment' (a ray nothing resolved
        that brings the environment) and 'none' (such a ray bringing nothing: fallback 'none');
        'rays' is the count of rays traced. Shares sum to 1 (all 0 when no ray was traced).
        'rejected' (a part of 'bvh'/'probes' + 'environment'): rays fallback_confidence sent to the
        fallback: rays the tracer handed over where they left the G-buffer's sight, and hits that
        failed the confidence test. Per ray: ray_sources()."""
        codes = self.ray_sources()
        smp = self.read("rays.sample")
        hit = self.read("rays.hit")
        traced = (smp[..., 3] > 0.5) & (smp[..., 0] > 0.0)
        n = int(traced.sum())
        share = (lambda m: float(m.sum()) / n) if n else (lambda m: 0.0)
        none = self.settings.method != "bvh" and self.settings.fallback == "none"
        rejected = traced & (hit[..., 2] < 0.5) & (hit[..., 3] < 0.0)
        out = {"rays": n, **{k: share(traced & (codes == i)) for i, k in enumerate(self.RAY_SOURCES) if i}}
        out["none"] = share(traced & (codes == 0)) if none else 0.0
        out["rejected"] = share(rejected)
        return {k: out[k] for k in ("rays", "screen", "bvh", "probes", "rejected", "environment", "none")}

    def reference(self, kind: str = "converged", *, rays: int | None = None, seed: int = 0,
                  sampling: str = "vndf", viewer: str = "ray", shadows: str = "traced", tracer: str = "auto",
                  progress=None):
        """Ground truth for this frame, traced against the scene's triangles (ssrlab.reference).

        kind="converged": `rays` rays per pixel (default 256; one for mirror pixels) drawn with
        `sampling`, the true reflection and final image. kind="per_ray": the rays this frame's
        SSR traced, each with its true hit. viewer="ray" (default) views the surfaces rays hit
        from the ray's origin: the physical reflection, which agrees with Mitsuba 3
        (ssrlab.crosscheck); viewer="camera" shades them as the camera sees them, like the lit
        G-buffer SSR fetches from, so that SSR and reference differ only by what screen space
        cannot see (only view-dependent specular changes between the two).

        The converged reference finds each pixel's surface point exactly (the camera ray traced
        against the triangles) and offsets reflection rays from it robustly (Waechter & Binder,
        Ray Tracing Gems ch. 6), independent of SSR's origin_bias. shadows="traced" (default)
        traces a shadow ray toward every light that casts a shadow from every shaded point, the
        pixel's own included; shadows="map" uses the frame's shadow maps as the lit G-buffer does
        (isolating what SSR itself gets wrong from the maps' blur; rendered again when a later
        frame took the renderer's shadow textures). Per-ray references
        trace the SSR rays as they were (from SSR's own origins).

        tracer: who traces the converged reference's rays. "cpu": Embree on every core with the
        shading ported to C++ (ray generation, materials, lights: the same formulas and RNG
        streams; shadows="traced" only); "embree": Embree intersecting for the GLSL shading;
        "glsl": the BVH traversed in the shader; "auto" (default) is "cpu" on the CPU device with
        traced shadows (the fastest there, measured) and "glsl" otherwise
        (docs/reference_tracers.md). They agree per pixel up to float evaluation order.
        Per-ray references trace in GLSL. `timings` names the stages (ms): reference.shade,
        reference.intersect, reference.transfer with "embree"; reference.cpu, reference.transfer
        with "cpu".
        progress: True shows a bar (tqdm on a terminal, a line per 10% otherwise), or a callable
        progress(done, total) called after each sample round (return False to stop). Ctrl-C
        stops a converged reference between sample rounds (KeyboardInterrupt).
        """
        if tracer not in ("auto", "cpu", "embree", "glsl"):
            raise ValueError(f"tracer must be 'auto', 'cpu', 'embree' or 'glsl', got {tracer!r}")
        if tracer == "cpu" and kind == "per_ray":
            raise ValueError("tracer='cpu' traces the converged reference only (per-ray references trace in GLSL)")
        if not (progress is None or isinstance(progress, bool) or callable(progress)):
            raise ValueError(f"progress must be None, a bool or a callable, got {progress!r}")
        if shadows not in ("traced", "map"):
            raise ValueError(f"shadows must be 'traced' or 'map', got {shadows!r}")
        if viewer not in ("camera", "ray"):
            raise ValueError(f"viewer must be 'camera' or 'ray', got {viewer!r}")
        from .truth.reference import ConvergedReference, PerRayReference

        if self._renderer is None or self._scene is None:
            raise ValueError("this frame does not know its renderer and scene")
        self._check_live("a reference")
        if kind not in ("per_ray", "converged"):
            raise ValueError(f"reference kind must be 'converged' or 'per_ray', got {kind!r}")
        # Every earlier reference of this frame keeps its values before the textures are reused.
        for result in list(self._results):
            result._keep()
        if kind == "per_ray":
            timings = self._renderer._native.reference(self._scene, self._native, "per_ray", 1, seed, sampling,
                                                      viewer, shadows)
            for name in ("reference.hit", "reference.position", "reference.radiance"):
                self._cache.pop(f"{name}@0", None)
            return PerRayReference(self, dict(timings))
        if kind == "converged":
            rays = 256 if rays is None else int(rays)
            from .progress import progress_callback

            names = ("reference.reflection", "reference.color", "reference.accum", "reference.direct")
            callback, close = progress_callback(progress, "reference")
            try:
                timings = self._renderer._native.reference(self._scene, self._native, "converged", rays, seed,
                                                          sampling, viewer, shadows, tracer, callback)
            finally:
                close()
                for name in names:  # also when stopped: the textures then hold a partial reference
                    self._cache.pop(f"{name}@0", None)
            timings = dict(timings)
            traced = timings.pop("reference.rays_traced", None)
            result = ConvergedReference(self, rays, timings)
            result.rays_traced = None if traced is None else int(traced)
            return result
        raise ValueError(f"reference kind must be 'converged' or 'per_ray', got {kind!r}")

    def save(self, folder, *, overwrite: bool = False, exposure: float = 1.0, extra: dict | None = None) -> list[Path]:
        """Writes color.png, gbuffer_layer<i>.exr and timings.json into `folder` (see ssrlab.io)."""
        from .io import write_frame

        return write_frame(self, folder, overwrite=overwrite, exposure=exposure, extra=extra)

    # -- display (ssrlab.display) ---------------------------------------------------------------
    def __repr__(self) -> str:
        s = self.settings
        total = self.timings.get("total")
        passes = [p for p in self.passes]
        ms = f", total {total:.2f} ms GPU" if total is not None else ""
        return (f"<Frame {s.width}x{s.height}, {s.layers} layer(s), method={s.method!r}, "
                f"passes {', '.join(passes)}{ms}>")
