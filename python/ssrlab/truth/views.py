"""Rich display of the references in Jupyter: the reference beside the frame and their error.

The truth's counterpart of ssrlab.display (whose tiles, grids and tables it uses): the
reference classes know nothing of how they are drawn; install() gives them their
representations when ssrlab.truth is first imported.
"""

from __future__ import annotations

import numpy as np

from ..display import _fit, colormap, figure, grid, png, srgb, table
from .metrics import error_image, flip_map, image_metrics
from .reference import ConvergedReference, PerRayReference, ReferenceImage, coverage


def error_tile(image: np.ndarray, truth: np.ndarray) -> tuple[np.ndarray, float]:
    """The per-pixel thesis error as a colour image, and the error shown as white (its 99th percentile)."""

    e = error_image(image, truth)
    top = float(np.percentile(e, 99)) if e.size else 0.0
    top = top if top > 0 else float(e.max()) if e.max() > 0 else 1.0
    return colormap(e, 0.0, top, "inferno"), top


def flip_tile(image: np.ndarray, truth: np.ndarray, dynamic_range: str = "ldr") -> tuple[np.ndarray, float] | None:
    """The FLIP error map (ssrlab.metrics.flip_map) through the magma colour map over FLIP's
    own range [0, 1], as FLIP's authors show it, and its mean; None without flip-evaluator."""

    try:
        e = flip_map(image, truth, dynamic_range)
    except ImportError:
        return None
    return colormap(e, 0.0, 1.0, "magma"), float(e.mean(dtype=np.float64))


def reference_tiles(truth_color, frame_color) -> list[tuple[np.ndarray, str]]:
    err, top = error_tile(frame_color, truth_color)
    tiles = [(srgb(truth_color), "reference"), (srgb(frame_color), "frame"),
             (err, f"error |frame − reference| summed over RGB: 0 … {top:.3g}")]
    flip = flip_tile(frame_color, truth_color)
    if flip is not None:
        tiles.append((flip[0], f"LDR-FLIP error map, 0 … 1 (mean {flip[1]:.4f})"))
    return tiles


def converged_png(ref) -> bytes:
    return png(grid([[t for t, _ in reference_tiles(ref.color, ref._frame.color)]]))


def converged_html(ref) -> str:

    m = image_metrics(ref._frame.color, ref.color, ref.reflective)
    stats = table(["", "thesis error", "RMSE", "PSNR dB", "LDR-FLIP", "HDR-FLIP", "SSIM"],
                  [[label] + [m[k + sfx] for k in ("thesis_error", "rmse", "psnr", "flip_ldr", "flip_hdr", "ssim")]
                   for label, sfx in (("all pixels", ""), ("reflective", "_reflective"))])
    return (f"<div><b>Converged reference, {ref.rays_per_pixel} ray(s) per reflective pixel</b>"
            f"{figure(reference_tiles(ref.color, ref._frame.color))}{stats}</div>")


def per_ray_summary(ref) -> list[list]:
    """Rows [quantity, value] of a per-ray reference."""
    frame = ref._frame
    hit, on_screen = ref.hit, ref.on_screen
    traced = np.broadcast_to(frame.rays.traced, hit.shape) & (frame.rays.weight > 0)
    n = int(traced.sum())
    rows = [["rays traced", n]]
    if n:
        rows += [["truly hit a surface", f"{100 * hit[traced].mean():.1f} %"],
                 ["true hit on screen", f"{100 * on_screen[traced].mean():.1f} %"],
                 ["true hit in a G-buffer layer", f"{100 * (ref.in_gbuffer >= 0)[traced].mean():.1f} %"]]

        rows.append(["SSR found the true surface (coverage)", f"{100 * coverage(frame, ref):.1f} %"])
    rows.append(["GPU ms", sum(v for k, v in ref.timings.items() if "." not in k and k != "total")])
    return rows


def per_ray_html(ref) -> str:
    return f"<div><b>Per-ray reference</b>{table(['', ''], per_ray_summary(ref))}</div>"


def reference_image_png(ref) -> bytes:
    return png(_fit(srgb(ref.color)))


def install() -> None:
    """Gives the reference classes their Jupyter representations."""
    ReferenceImage._repr_png_ = lambda self: reference_image_png(self)
    ConvergedReference._repr_png_ = lambda self: converged_png(self)  # reference, frame, error
    ConvergedReference._repr_html_ = lambda self: converged_html(self)
    PerRayReference._repr_html_ = lambda self: per_ray_html(self)
