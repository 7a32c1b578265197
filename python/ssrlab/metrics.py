"""Image error metrics: how far a rendered image is from a reference image.

Pure numpy; every sum is accumulated in float64 whatever the input precision. Images are
(H, W, C) arrays of linear radiance (C = 3 for RGB); a mask is an (H, W) boolean array that
selects the pixels a metric is taken over (all pixels when no mask is given). With N the
number of selected pixels, C the channel count, a the image and b the reference:

thesis_error  E = (1 / N) * sum_p sum_c |a_pc - b_pc|
              the thesis's error (seed 000, section 3.1.2): the absolute colour differences
              of every pixel, summed over R, G and B, divided by the pixel count so that it
              does not depend on the resolution.
rmse          sqrt( (1 / (N C)) * sum_p sum_c (a_pc - b_pc)^2 )
              root mean square error per channel value.
psnr          10 log10(peak^2 / mse) dB, mse = rmse^2; identical images (mse = 0) get
              PSNR_CAP_DB instead of infinity, and no value exceeds it, so results stay
              finite numbers that tables, JSON and plots can hold.

Inputs with NaN or Inf values raise ValueError: an error metric over them would be
meaningless (a NaN poisons every sum) and usually points at a rendering bug.
"""

from __future__ import annotations

import numpy as np

# PSNR of identical images, and the largest PSNR reported. 100 dB is an RMSE of 1e-5 of the
# peak, far below what float32 rendering differences or 8-bit quantisation resolve.
PSNR_CAP_DB = 100.0


def _as_image(a, name: str) -> np.ndarray:
    """`a` as a float64 (H, W, C) array; raises ValueError naming `name` if it is not one."""
    try:
        arr = np.asarray(a)
    except Exception as e:  # e.g. ragged nested lists
        raise ValueError(f"{name} must be an (H, W, C) array: {e}") from None
    if arr.dtype == np.bool_ or not (np.issubdtype(arr.dtype, np.floating) or np.issubdtype(arr.dtype, np.integer)):
        raise ValueError(f"{name} must be a numeric array, got dtype {arr.dtype}")
    if arr.ndim != 3 or 0 in arr.shape:
        raise ValueError(f"{name} must be a non-empty (H, W, C) array, got shape {arr.shape}")
    arr = arr.astype(np.float64, copy=False)
    bad = ~np.isfinite(arr)
    if bad.any():
        raise ValueError(f"{name} contains {int(bad.sum())} NaN/Inf value(s)")
    return arr


def _pair(image, reference) -> tuple[np.ndarray, np.ndarray]:
    a, b = _as_image(image, "image"), _as_image(reference, "reference")
    if a.shape != b.shape:
        raise ValueError(f"image and reference must have the same shape, got image {a.shape} "
                         f"and reference {b.shape}")
    return a, b


def _selected(a: np.ndarray, b: np.ndarray, mask) -> tuple[np.ndarray, np.ndarray]:
    """The (N, C) pixel values of both images selected by `mask` (all pixels for None)."""
    if mask is None:
        return a.reshape(-1, a.shape[2]), b.reshape(-1, b.shape[2])
    m = np.asarray(mask)
    if m.dtype != np.bool_:
        raise ValueError(f"mask must be a boolean array, got dtype {m.dtype}")
    if m.shape != a.shape[:2]:
        raise ValueError(f"mask must have the image's (H, W) shape {a.shape[:2]}, got {m.shape}")
    if not m.any():
        raise ValueError("mask selects no pixel: a mean over no pixels is undefined")
    return a[m], b[m]


def thesis_error(image, reference, mask=None) -> float:
    """The thesis's error: sum over the selected pixels of sum_c |image - reference|,
    divided by the number of selected pixels (see the module documentation)."""
    a, b = _selected(*_pair(image, reference), mask)
    return float(np.abs(a - b).sum(dtype=np.float64) / a.shape[0])


def _mse(image, reference, mask) -> float:
    a, b = _selected(*_pair(image, reference), mask)
    d = a - b
    return float(np.square(d).sum(dtype=np.float64) / d.size)


def rmse(image, reference, mask=None) -> float:
    """Root mean square error over every channel value of the selected pixels."""
    return float(np.sqrt(_mse(image, reference, mask)))


def _psnr_from_mse(mse: float, peak: float) -> float:
    if mse == 0.0:
        return PSNR_CAP_DB
    return float(min(PSNR_CAP_DB, 10.0 * np.log10(peak * peak / mse)))


def psnr(image, reference, mask=None, peak: float = 1.0) -> float:
    """Peak signal-to-noise ratio in dB, 10 log10(peak^2 / mse), capped at PSNR_CAP_DB
    (identical images get the cap rather than infinity). `peak` is the signal's nominal
    maximum: 1.0 for linear radiance displayed at exposure 1."""
    if isinstance(peak, bool) or not isinstance(peak, (int, float, np.integer, np.floating)):
        raise ValueError(f"peak must be a positive number, got {peak!r}")
    if not (np.isfinite(peak) and peak > 0):
        raise ValueError(f"peak must be a positive finite number, got {peak!r}")
    return _psnr_from_mse(_mse(image, reference, mask), float(peak))


def error_image(image, reference) -> np.ndarray:
    """Per-pixel error: sum over channels of |image - reference|, as an (H, W) float32 array
    (the thesis error is its mean)."""
    a, b = _pair(image, reference)
    return np.abs(a - b).sum(axis=2, dtype=np.float64).astype(np.float32)


def image_metrics(image, reference, reflective_mask) -> dict[str, float | None]:
    """Every metric of `image` against `reference`, over the whole image and over the
    reflective pixels (`reflective_mask`, (H, W) bool, e.g. ReferenceImage.reflective).

    Keys: thesis_error, rmse, psnr (whole image) and thesis_error_reflective,
    rmse_reflective, psnr_reflective (reflective pixels; None when no pixel reflects, since
    a mean over no pixels is undefined).
    """
    a, b = _pair(image, reference)
    m = np.asarray(reflective_mask)
    if m.dtype != np.bool_ or m.shape != a.shape[:2]:
        raise ValueError(f"reflective_mask must be a boolean (H, W) = {a.shape[:2]} array, "
                         f"got dtype {m.dtype} and shape {m.shape}")
    out: dict[str, float | None] = {
        "thesis_error": thesis_error(a, b),
        "rmse": rmse(a, b),
        "psnr": psnr(a, b),
    }
    if m.any():
        out.update(thesis_error_reflective=thesis_error(a, b, m), rmse_reflective=rmse(a, b, m),
                   psnr_reflective=psnr(a, b, m))
    else:
        out.update(thesis_error_reflective=None, rmse_reflective=None, psnr_reflective=None)
    return out


METRIC_KEYS = ("thesis_error", "rmse", "psnr", "thesis_error_reflective", "rmse_reflective", "psnr_reflective")

__all__ = ["PSNR_CAP_DB", "METRIC_KEYS", "thesis_error", "rmse", "psnr", "error_image", "image_metrics"]


def coverage(frame, truth=None, *, tolerance_px: float = 1.0) -> float:
    """Share of the rays that truly hit a surface for which SSR found that surface (see
    ssrlab.reference.coverage; `truth` is frame.reference("per_ray"), computed when omitted)."""
    from . import reference

    return reference.coverage(frame, truth, tolerance_px=tolerance_px)


def hit_position_error(frame, truth=None) -> np.ndarray:
    """Pixels between SSR's hit and the true hit, per ray where both hit on screen (see
    ssrlab.reference.hit_position_error)."""
    from . import reference

    return reference.hit_position_error(frame, truth)
