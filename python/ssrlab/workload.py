"""What a render will cost, known before it starts.

A glTF file of a few megabytes can instance one mesh tens of thousands of times: tens of millions
of triangles, which load in a fraction of a second and then take minutes to draw on llvmpipe. So
before a render (Renderer.render, render_sequence, prepare) the renderer counts the work: the
scene's drawn triangles (Scene.triangle_count, an instanced mesh once per instance), the geometry
passes the settings make over them, and a BVH of every triangle where the settings trace one.
With the device's rates that is an estimate in seconds (Renderer.estimate, an `Estimate`):

- where it reaches LONG_SECONDS, a `SceneWarning` says so before the work starts, naming the
  scene, the triangle count and the estimate;
- where the scene has more triangles than the renderer's budget (Renderer(max_triangles=N),
  Renderer.max_triangles, $SSRLAB_MAX_TRIANGLES), the render is refused with a `SceneError`
  naming the scene, the triangle count, the budget and how to raise it; nothing is drawn.

The estimate is rough by design: it counts triangles, not the pixels they cover. It leans long
where the triangles are the work (copies spread over the view, most of them small or outside it)
and may fall short where the fill is (copies stacked in one place, each covering what the others
do). `python benchmarks/timing/render_estimate.py --device cpu` prints it beside the first and a repeated
render of both kinds of scene, and the rates below come from what it measures on llvmpipe.
"""

from __future__ import annotations

import dataclasses
import math
import os
import warnings

from . import _core
from .scene import SceneWarning

MAX_TRIANGLES_ENV = "SSRLAB_MAX_TRIANGLES"

# Estimated seconds from which a render warns before it starts.
LONG_SECONDS = 10.0

# The rates the estimate assumes, per device: "draw", triangles a second through one geometry
# pass (every triangle of the scene drawn once: a depth or shading pass of a layer, a shadow map's
# face), and "bvh", triangles a second of the extra work of a first render that traces the scene's
# BVH (method "bvh", fallbacks "bvh" and "probes"): its build, once per scene geometry, and the
# first frame's tracing of it (the tracing of later frames is not counted). From the first renders
# of `python benchmarks/timing/render_estimate.py --device cpu` on llvmpipe (2 cores, shared): each at or
# below its column ("draw rate", "bvh rate") on every spread scene, where triangles are the work,
# and within that column's range over the stacked ones, where the overlap is (the fill, and rays
# that meet every copy), which a count of triangles cannot see: there the estimate may fall
# short by the spread of that range, and the spread scenes take less than it says. A hardware device
# draws faster than llvmpipe: no committed run measures its rate, so it is estimated at llvmpipe's
# (an upper bound of its time) unless Renderer.triangle_rates is set to what that command prints
# there with --device gpu.
RATES = {"cpu": {"draw": 1e6, "bvh": 8e4}}


@dataclasses.dataclass(frozen=True)
class Estimate:
    """What a render (or a sequence of `frames`) will cost on a renderer's device, before it starts.

    triangles: the scene's drawn triangles (instances included); passes: geometry passes over them
    in all (every frame's, and deep_gbuffer 'auto''s measurement where it will measure);
    per_frame: the passes of one frame and what they are; bvh: whether a BVH of every triangle is
    built first; seconds: the estimate; rates: the device's rates it assumes (RATES);
    measured_rates: whether those were measured on this kind of device (False: a hardware device
    estimated at llvmpipe's rates, an upper bound)."""

    scene: str
    device: str
    triangles: int
    frames: int
    passes: int
    per_frame: tuple[tuple[str, int], ...]
    bvh: bool
    seconds: float
    rates: dict
    measured_rates: bool

    @property
    def long(self) -> bool:
        """Whether the render warns before it starts (seconds >= LONG_SECONDS)."""
        return self.seconds >= LONG_SECONDS

    def describe(self) -> str:
        """The work in words: passes, BVH and the time, e.g. for a progress line."""
        parts = "; ".join(f"{what}: {n}" for what, n in self.per_frame)
        frames = f" a frame over {self.frames} frames" if self.frames > 1 else ""
        extra = self.passes - self.frames * sum(n for _, n in self.per_frame)
        measure = f"; {extra} more measuring deep_gbuffer='auto'" if extra > 0 else ""
        bvh = ", and a BVH of every triangle built and traced" if self.bvh else ""
        bound = "about" if self.measured_rates else "at most about"
        return (f"{self.triangles:,} triangles, {sum(n for _, n in self.per_frame)} geometry passes{frames} "
                f"({parts}{measure}){bvh}: {bound} {_duration(self.seconds)} on this device ({self.device})")


def _duration(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def check_budget(value, name: str = "Renderer.max_triangles") -> int | None:
    """A triangle budget: an int >= 1, or None (or 0) for none; ValueError naming `name` otherwise."""
    if value is None:
        return None
    if isinstance(value, bool):
        raise ValueError(f"{name} must be a whole number of triangles (or None for no budget), got {value!r}")
    if not isinstance(value, int):
        try:  # numpy integers and the like
            import operator

            value = operator.index(value)
        except TypeError:
            raise ValueError(f"{name} must be a whole number of triangles (or None for no budget), "
                             f"got {value!r}") from None
    if value < 0:
        raise ValueError(f"{name} must be >= 1 triangle (or None for no budget), got {value}")
    return None if value == 0 else int(value)


def budget_from_env() -> int | None:
    """$SSRLAB_MAX_TRIANGLES as a budget (a whole number, 20000000 or 2e7), None where unset or empty."""
    text = os.environ.get(MAX_TRIANGLES_ENV, "").strip().replace("_", "")
    if not text:
        return None
    try:
        number = float(text)
    except ValueError:
        number = math.nan
    if not math.isfinite(number) or number != math.floor(number) or number < 0:
        raise ValueError(f"${MAX_TRIANGLES_ENV} must be a whole number of triangles (e.g. 20000000 or 2e7; "
                         f"0 or empty for no budget), got {os.environ[MAX_TRIANGLES_ENV]!r}")
    return check_budget(int(number), f"${MAX_TRIANGLES_ENV}")


# Geometry passes one layer of each construction of the deep G-buffer makes over the scene
# (peeling: a depth pass and a shading pass per layer; the visibility buffer one id pass per layer;
# the lists one pass for every layer), with `layers` layers.
def _construction_passes(method: str, layers: int) -> int:
    return {"peel": 2 * layers, "visibility": layers, "lists": 1, "visibility_lists": 1}[method]


def frame_passes(settings, scene) -> tuple[tuple[str, int], ...]:
    """The geometry passes one frame makes over the scene's triangles, by what they are. With
    deep_gbuffer 'auto' the construction is not known before it is measured: peeling's, the
    most passes, is counted."""
    method = "peel" if settings.deep_gbuffer == "auto" else settings.deep_gbuffer
    name = {"peel": "peeling", "visibility": "visibility buffer", "lists": "fragment lists",
            "visibility_lists": "visibility lists"}[method]
    layers = f"{settings.layers} layer" + ("s" if settings.layers > 1 else "")
    out = [(f"{name}, {layers}", _construction_passes(method, settings.layers))]
    if settings.shadow_map_size > 0:
        faces = sum(6 if light.type == "point" else 1 for light in scene.lights if light.cast_shadow)
        if faces:
            out.append(("shadow map faces", faces))
    return tuple(out)


def auto_measurement_passes(settings, device: str) -> int:
    """The geometry passes deep_gbuffer 'auto' spends measuring the constructions (4 renders of
    each, G-buffer only), as Renderer._measure_deep_gbuffer does; 0 where it measures nothing."""
    if settings.deep_gbuffer != "auto":
        return 0
    methods = _core.deep_gbuffer_candidates(device == "cpu", settings.layers)
    if len(methods) == 1:
        return 0
    return 4 * sum(_construction_passes(m, settings.layers) for m in methods)


def needs_bvh(settings) -> bool:
    """Whether the settings trace the scene's BVH (method "bvh", fallback "bvh" or "probes")."""
    return settings.method == "bvh" or settings.fallback in ("bvh", "probes")


def estimate(scene, settings, *, device: str, frames: int = 1, measures_auto: bool = True,
             builds_bvh: bool = True, rates: dict | None = None) -> Estimate:
    """The Estimate of rendering `scene` with `settings` `frames` times on `device` ("cpu",
    "gpu:N"): `measures_auto` whether deep_gbuffer 'auto' will measure first, `builds_bvh` whether
    the BVH is not built yet; `rates` the device's (default RATES)."""
    measured = device in RATES
    rates = dict(rates if rates is not None else RATES.get(device, RATES["cpu"]))
    triangles = int(scene.triangle_count)
    per_frame = frame_passes(settings, scene)
    passes = frames * sum(n for _, n in per_frame)
    if measures_auto:
        passes += auto_measurement_passes(settings, device)
    bvh = needs_bvh(settings) and builds_bvh
    seconds = triangles * passes / rates["draw"] + (triangles / rates["bvh"] if bvh else 0.0)
    return Estimate(scene=scene.name, device=device, triangles=triangles, frames=frames, passes=passes,
                    per_frame=per_frame, bvh=bvh, seconds=seconds, rates=rates, measured_rates=measured)


def check(est: Estimate, budget: int | None, what: str, stacklevel: int) -> None:
    """Refuses `est` beyond `budget` (SceneError), warns where it is long (SceneWarning); `what`
    names the call ("Renderer.render")."""
    if budget is not None and est.triangles > budget:
        raise _core.SceneError(
            f"{what}: scene {est.scene!r} draws {est.triangles:,} triangles (instances included), beyond this "
            f"renderer's budget of {budget:,} triangles (max_triangles); nothing was rendered. To render it, "
            f"raise the budget: Renderer(max_triangles={_round_up(est.triangles)}), renderer.max_triangles = "
            f"None (no budget) or ${MAX_TRIANGLES_ENV}={_round_up(est.triangles)} (the work: "
            f"{est.describe()})")
    if est.long:
        warnings.warn(
            f"{what}: scene {est.scene!r} is long work: {est.describe()}, before the call returns. "
            f"Renderer(max_triangles=N) or ${MAX_TRIANGLES_ENV}=N refuses scenes of more than N triangles "
            f"instead", SceneWarning, stacklevel=stacklevel + 1)


def _round_up(n: int) -> str:
    """n rounded up to 2 significant digits, written with underscores (a budget to copy)."""
    if n < 100:
        return str(n)
    scale = 10 ** (len(str(n)) - 2)
    return f"{-(-n // scale) * scale:_}"


__all__ = ["Estimate", "LONG_SECONDS", "MAX_TRIANGLES_ENV", "RATES", "budget_from_env", "check_budget", "estimate",
           "frame_passes", "needs_bvh"]
