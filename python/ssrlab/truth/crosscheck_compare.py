"""The cross-check's comparisons: the ssrlab side (a frame and its converged reference, still or
after objects moved, with the most exact reference options), the floor's pixels they are compared
on, and the statistics that separate a bias from the two renderers' Monte-Carlo noise."""

from __future__ import annotations

import inspect

import numpy as np

from ..settings import Settings
from .crosscheck_scenes import FLOOR, crosscheck_scene, move_objects


def floor_pixels(frame, floor_object: int = FLOOR, *, interior: bool = True) -> np.ndarray:
    """(H, W) bool: pixels whose layer 0 shows the floor; with interior=True also every
    8-neighbour (silhouette pixels, where a pixel-centre sample lands on either side, are left
    out)."""
    g = frame.gbuffer
    m = g.coverage[0] & (g.object_id[0] == floor_object)
    if interior:
        p = np.pad(m, 1, constant_values=False)
        H, W = m.shape
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                m = m & p[1 + dy:1 + dy + H, 1 + dx:1 + dx + W]
    return m


def _setting_names() -> set:
    return {f for f in Settings.__dataclass_fields__}


def exact_options(settings: Settings) -> tuple[Settings, dict, list[str]]:
    """`settings` with the most exact reference options this ssrlab has (detected, so the same
    code runs before and after they exist), the matching keyword arguments of
    ``frame.reference`` and a list of what was turned on."""
    names = _setting_names()
    changes, used = {}, []
    if "reference_shadows" in names:
        changes["reference_shadows"] = "traced"
        used.append("reference_shadows='traced'")
    s = settings.replace(**changes) if changes else settings
    kwargs = {}
    from ..renderer import Frame

    viewer = inspect.signature(Frame.reference).parameters.get("viewer")
    if viewer is not None and viewer.default != "ray":
        # The physical view of the reflected surface: its specular seen from the floor point.
        kwargs["viewer"] = "ray"
        used.append("viewer='ray'")
    return s, kwargs, used


def ssrlab_reference(renderer, scene, settings: Settings, *, rays: int = 256, seed: int = 0, **reference_kwargs):
    """The frame (method off) and its converged reference: (frame, truth)."""
    frame = renderer.render(scene, settings=settings.replace(method="off"))
    truth = frame.reference("converged", rays=rays, seed=seed, **reference_kwargs)
    return frame, truth

def moved_reference(renderer, scene, settings: Settings, *, rays: int = 256, seed: int = 0, moves=None,
                    **reference_kwargs):
    """The second frame of a two-frame sequence (method off, one camera) whose objects `moves`
    moved after the first (move_objects), and its converged reference: (frame, truth). The scene
    is left moved, as mitsuba_scene must see it."""
    frames = renderer.render_sequence(scene, [scene.camera, scene.camera], settings.replace(method="off"))
    next(frames)
    move_objects(scene, moves)
    frame = next(frames)
    frames.close()
    return frame, frame.reference("converged", rays=rays, seed=seed, **reference_kwargs)


def floor_psnr(image, reference, mask) -> float:
    from .metrics import psnr

    return psnr(image, reference, mask)


def noise_split(ssr_a, ssr_b, mit_a, mit_b, mask) -> dict:
    """Separates bias from Monte-Carlo noise, for two independent ssrlab references (seeds a, b)
    and two independent Mitsuba images: with independent noise,
    E|s - m|^2 = var_s + var_m + bias^2, var_s = E|s_a - s_b|^2 / 2, var_m likewise. Returns the
    MSEs (per channel value over `mask`) and the bias estimate (may come out slightly negative)."""
    def mse(a, b):
        return float(np.mean((a[mask] - b[mask]) ** 2))

    cross = mse(ssr_a, mit_a)
    var_s = mse(ssr_a, ssr_b) / 2.0
    var_m = mse(mit_a, mit_b) / 2.0
    return {"mse": cross, "noise_ssrlab": var_s, "noise_mitsuba": var_m, "bias2": cross - var_s - var_m,
            "ratio": cross / max(var_s + var_m, 1e-30)}


def mean_ratio(ssr_a, ssr_b, mit_a, mit_b, mask) -> tuple[float, float]:
    """Mean floor radiance of ssrlab over Mitsuba (each the mean of its two images) and the
    ratio's standard error from the per-pixel spread of the differences (pixels' noise is
    independent): a brightness bias shows as a ratio many standard errors away from 1."""
    s = (ssr_a[mask] + ssr_b[mask]) / 2.0
    m = (mit_a[mask] + mit_b[mask]) / 2.0
    d = (s - m).mean(axis=1)  # per pixel, over RGB
    mean_m = float(m.mean())
    ratio = float(s.mean()) / max(mean_m, 1e-30)
    err = float(d.std(ddof=1) / np.sqrt(max(len(d), 1))) / max(mean_m, 1e-30)
    return ratio, err


def noise_agreement(ssr_a, ssr_b, mit_a, mit_b, mask) -> dict:
    """Whether two renderers agree to their Monte-Carlo noise, for two independent ssrlab
    references (seeds a, b) and two independent Mitsuba images, in standard errors measured from
    the images themselves. Per pixel of `mask` (RGB averaged: a pixel's channels share its
    paths), d = (s_a + s_b) / 2 - (m_a + m_b) / 2 and v = ((s_a - s_b)^2 + (m_a - m_b)^2) / 4,
    whose expectation is d's variance when the noise is independent; so E[d^2 - v] is the squared
    bias. Pixels' noise is independent, so over N pixels:

    * ``z_mean``: mean(d) / (std(d) / sqrt(N)), a brightness bias (a Fresnel factor, a missing
      energy term) in standard errors;
    * ``z_bias2``: mean(d^2 - v) / (std(d^2 - v) / sqrt(N)), any per-pixel bias (a lobe of the
      wrong shape or width moves light between pixels without changing the mean) in standard
      errors.

    With ``mean_relative`` (mean(d) over Mitsuba's mean) and ``mse_over_noise`` (mean(d^2) /
    mean(v), 1 for unbiased images)."""
    s_a, s_b, m_a, m_b = (np.asarray(x, np.float64)[mask].mean(axis=-1) for x in (ssr_a, ssr_b, mit_a, mit_b))
    d = (s_a + s_b) / 2.0 - (m_a + m_b) / 2.0
    v = ((s_a - s_b) ** 2 + (m_a - m_b) ** 2) / 4.0
    t = d * d - v
    n = max(len(d), 2)
    se_mean = float(d.std(ddof=1)) / np.sqrt(n)
    se_bias2 = float(t.std(ddof=1)) / np.sqrt(n)
    mean_m = float(((m_a + m_b) / 2.0).mean())
    return {"pixels": int(len(d)), "z_mean": float(d.mean()) / max(se_mean, 1e-30),
            "z_bias2": float(t.mean()) / max(se_bias2, 1e-30), "bias2": float(t.mean()), "se_bias2": se_bias2,
            "mean_relative": float(d.mean()) / max(mean_m, 1e-30),
            "se_mean_relative": se_mean / max(mean_m, 1e-30),
            "mse_over_noise": float(np.mean(d * d)) / max(float(np.mean(v)), 1e-30), "noise": float(np.mean(v))}


def reference_ignores_origin_bias(renderer, width: int = 48, height: int = 32) -> bool:
    """Whether this ssrlab's converged reference offsets its ray origins independently of
    `origin_bias` (the reference's robust offset): two tiny references of the mirror scene with
    origin_bias 0.002 and 0.05 come out identical."""
    scene = crosscheck_scene(0.0)
    s = Settings(width=width, height=height)
    _, a = ssrlab_reference(renderer, scene, s.replace(origin_bias=0.002), rays=1)
    a = a.color.copy()
    _, b = ssrlab_reference(renderer, scene, s.replace(origin_bias=0.05), rays=1)
    return bool(np.array_equal(a, b.color))
