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

flip_ldr      mean of the LDR-FLIP error map (Andersson et al. 2020, "FLIP: A Difference
              Evaluator for Alternating Images"), computed by NVIDIA's reference
              implementation (PyPI flip-evaluator): both images clamped to [0, 1] (the
              image as displayed at exposure 1, like ssrlab.io.linear_to_srgb) and compared
              as linear RGB. In [0, 1], 0 for identical images; lower is better.
flip_hdr      mean of the HDR-FLIP error map (Andersson et al. 2021, "Visualizing Errors in
              Rendered High Dynamic Range Images"): linear radiance, negative values clamped
              to 0, LDR-FLIP over the exposure range computed from the reference (ACES tone
              mapper, the implementation's defaults). Lower is better.
ssim          mean structural similarity (Wang et al. 2004) by scikit-image's
              structural_similarity on the displayed images (clamped to [0, 1], sRGB-encoded),
              with the paper's Gaussian 11-tap window (sigma 1.5) and population covariances,
              data_range 1, averaged over R, G and B. 1 for identical images; higher is better.
              None for images smaller than the 11x11 window.

Both viewing-condition parameters of FLIP are its defaults: 67 pixels per degree (a 0.7 m
viewing distance of a 0.7 m wide, 3840 pixel display). The FLIP and SSIM packages are
optional (``pip install 'ssrlab[metrics]'``): without them image_metrics reports None under
their keys and warns once; flip() and ssim() raise ImportError naming the extra. FLIP's filters
are large and fixed in size (67 pixels per degree), so it costs far more than the other metrics
(tens of milliseconds for a small image, about 0.3 s at 320x180 and 3 s at 640x360 on one CPU
core; benchmarks/timing/metric_cost.py): SSRLAB_PERCEPTUAL=0 leaves
FLIP and SSIM out of image_metrics (and so of sweep rows) unless asked for.

Inputs with NaN or Inf values raise ValueError: an error metric over them would be
meaningless (a NaN poisons every sum) and usually points at a rendering bug.
"""

from __future__ import annotations

import os
import warnings

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


# -- perceptual and structural metrics (libraries, never re-implemented here) ---------------------------
_EXTRA_HINT = "pip install 'ssrlab[metrics]'"
FLIP_RANGES = ("ldr", "hdr")
# SSIM as Wang et al. (2004), section III-C: an 11x11 circular-symmetric Gaussian window with
# standard deviation 1.5 and population (not sample) covariances.
SSIM_SIGMA = 1.5
SSIM_WINDOW = 11


def _flip_module():
    try:
        import flip_evaluator
    except ImportError as e:
        raise ImportError(f"FLIP needs NVIDIA's flip-evaluator package: {_EXTRA_HINT} "
                          f"(or pip install flip-evaluator); {e}") from None
    return flip_evaluator


def _skimage_metrics():
    try:
        from skimage import metrics as skm
    except ImportError as e:
        raise ImportError(f"SSIM needs scikit-image: {_EXTRA_HINT} (or pip install scikit-image); {e}") from None
    return skm


def _rgb(a: np.ndarray, name: str) -> np.ndarray:
    if a.shape[2] != 3:
        raise ValueError(f"{name} must have 3 (RGB) channels for FLIP and SSIM, got {a.shape[2]}")
    return a


def flip_map(image, reference, dynamic_range: str = "ldr") -> np.ndarray:
    """The per-pixel FLIP error (H, W) float32 in [0, 1] of `image` against `reference`
    (see the module documentation for how linear radiance is handed to FLIP)."""
    if dynamic_range not in FLIP_RANGES:
        raise ValueError(f"dynamic_range must be one of {', '.join(FLIP_RANGES)}, got {dynamic_range!r}")
    fe = _flip_module()
    a, b = _pair(image, reference)
    a, b = _rgb(a, "image"), _rgb(b, "reference")
    if dynamic_range == "ldr":
        # LDR-FLIP compares displayed images: what exposure 1 shows, linear RGB in [0, 1].
        test, ref = np.clip(a, 0.0, 1.0), np.clip(b, 0.0, 1.0)
        args = ("LDR",)
        kwargs = {"inputsRGB": False}
    else:
        test, ref = np.maximum(a, 0.0), np.maximum(b, 0.0)
        args = ("HDR",)
        kwargs = {}
    error, _, _ = fe.evaluate(np.ascontiguousarray(ref, np.float32), np.ascontiguousarray(test, np.float32), *args,
                              applyMagma=False, computeMeanError=False, **kwargs)
    return np.asarray(error, np.float32).reshape(a.shape[:2])


def flip(image, reference, mask=None, dynamic_range: str = "ldr") -> float:
    """Mean FLIP error (LDR or HDR, see the module documentation) over the selected pixels;
    the mean over all pixels is flip-evaluator's own mean FLIP error."""
    error = flip_map(image, reference, dynamic_range)
    if mask is None:
        return float(error.mean(dtype=np.float64))
    m = _check_mask(mask, error.shape)
    return float(error[m].mean(dtype=np.float64))


def _check_mask(mask, shape) -> np.ndarray:
    m = np.asarray(mask)
    if m.dtype != np.bool_:
        raise ValueError(f"mask must be a boolean array, got dtype {m.dtype}")
    if m.shape != tuple(shape):
        raise ValueError(f"mask must have the image's (H, W) shape {tuple(shape)}, got {m.shape}")
    if not m.any():
        raise ValueError("mask selects no pixel: a mean over no pixels is undefined")
    return m


def ssim_map(image, reference) -> np.ndarray | None:
    """scikit-image's per-pixel SSIM (H, W) (the mean over R, G and B) of the displayed images,
    or None when the image is smaller than the window."""
    skm = _skimage_metrics()
    a, b = _pair(image, reference)
    a, b = _rgb(a, "image"), _rgb(b, "reference")
    if min(a.shape[:2]) < SSIM_WINDOW:
        return None
    from ..io import linear_to_srgb

    _, full = skm.structural_similarity(linear_to_srgb(a).astype(np.float64), linear_to_srgb(b).astype(np.float64),
                                        channel_axis=2, data_range=1.0, gaussian_weights=True, sigma=SSIM_SIGMA,
                                        use_sample_covariance=False, full=True)
    return full.mean(axis=2)


def ssim(image, reference, mask=None) -> float | None:
    """Mean SSIM (see the module documentation) over the selected pixels; over all pixels it
    is scikit-image's own mean (which leaves out the border half a window wide, where the
    window does not fit; so does the masked mean). None for images smaller than the window."""
    full = ssim_map(image, reference)
    if full is None:
        return None
    pad = (SSIM_WINDOW - 1) // 2
    inner = np.zeros(full.shape, bool)
    inner[pad:full.shape[0] - pad, pad:full.shape[1] - pad] = True
    if mask is not None:
        inner &= _check_mask(mask, full.shape)
        if not inner.any():
            return None  # the selected pixels all lie in the border no window covers
    return float(full[inner].mean(dtype=np.float64))


PERCEPTUAL_KEYS = ("flip_ldr", "flip_hdr", "ssim")
# SSRLAB_PERCEPTUAL=0 leaves FLIP and SSIM out of image_metrics by default (sweep rows included).
PERCEPTUAL_ENV = "SSRLAB_PERCEPTUAL"
_WARNED: set[str] = set()


def perceptual_available() -> bool:
    """True when flip-evaluator and scikit-image can be imported."""
    try:
        _flip_module()
        _skimage_metrics()
    except ImportError:
        return False
    return True


def image_metrics(image, reference, reflective_mask, *, perceptual: bool | None = None) -> dict[str, float | None]:
    """Every metric of `image` against `reference`, over the whole image and over the
    reflective pixels (`reflective_mask`, (H, W) bool, e.g. ReferenceImage.reflective).

    Keys: thesis_error, rmse, psnr, flip_ldr, flip_hdr, ssim (whole image) and the same with
    _reflective (reflective pixels; None when no pixel reflects, since a mean over no pixels
    is undefined). `perceptual`: True computes FLIP and SSIM (ImportError without their
    packages); False leaves them None; None (default) computes them where the packages are
    installed (else leaves them None with a warning naming the pip extra) unless
    $SSRLAB_PERCEPTUAL is 0.
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
    any_reflective = bool(m.any())
    if any_reflective:
        out.update(thesis_error_reflective=thesis_error(a, b, m), rmse_reflective=rmse(a, b, m),
                   psnr_reflective=psnr(a, b, m))
    else:
        out.update(thesis_error_reflective=None, rmse_reflective=None, psnr_reflective=None)
    for k in PERCEPTUAL_KEYS:
        out[k] = out[k + "_reflective"] = None
    if perceptual is None and os.environ.get(PERCEPTUAL_ENV, "").strip().lower() in ("0", "off", "no", "false"):
        perceptual = False  # FLIP costs up to seconds an image on a CPU core: a sweep may not want it
    if perceptual is None:
        perceptual = perceptual_available()
        if not perceptual and "missing" not in _WARNED:
            _WARNED.add("missing")
            warnings.warn(f"ssrlab.metrics: FLIP and SSIM are left out (None): {_EXTRA_HINT}", stacklevel=2)
    if perceptual and a.shape[2] == 3:
        for rng in FLIP_RANGES:
            error = flip_map(a, b, rng)
            out[f"flip_{rng}"] = float(error.mean(dtype=np.float64))
            if any_reflective:
                out[f"flip_{rng}_reflective"] = float(error[m].mean(dtype=np.float64))
        out["ssim"] = ssim(a, b)
        if any_reflective:
            out["ssim_reflective"] = ssim(a, b, m)
    return out


METRIC_KEYS = ("thesis_error", "rmse", "psnr", "thesis_error_reflective", "rmse_reflective", "psnr_reflective",
               "flip_ldr", "flip_hdr", "ssim", "flip_ldr_reflective", "flip_hdr_reflective", "ssim_reflective")
# Metrics where a larger value is better; every other metric is an error (lower is better).
HIGHER_IS_BETTER = ("psnr", "psnr_reflective", "ssim", "ssim_reflective")

__all__ = ["PSNR_CAP_DB", "METRIC_KEYS", "PERCEPTUAL_KEYS", "HIGHER_IS_BETTER", "thesis_error", "rmse", "psnr",
           "error_image", "image_metrics", "flip", "flip_map", "ssim", "ssim_map", "perceptual_available"]


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
