"""FLIP and SSIM in image_metrics: the values of flip-evaluator and scikit-image themselves."""

import numpy as np
import pytest

from ssrlab import bench, metrics

flip_evaluator = pytest.importorskip("flip_evaluator")
skm = pytest.importorskip("skimage.metrics")

RNG = np.random.default_rng(26)
# A 48x64 linear-radiance pair: a smooth gradient with highlights above 1 (so LDR and HDR FLIP
# differ) and a noisy, darker copy.
_y, _x = np.mgrid[0:48, 0:64] / np.array([47.0, 63.0])[:, None, None]
REFERENCE = np.stack([_x, _y, 0.5 * (_x + _y)], -1) * 1.6
REFERENCE[10:20, 30:40] = 4.0
IMAGE = np.clip(0.85 * REFERENCE + 0.05 * RNG.standard_normal(REFERENCE.shape), 0.0, None)
MASK = np.zeros(REFERENCE.shape[:2], bool)
MASK[5:40, 8:50] = True


def _srgb(a):
    x = np.clip(a, 0, 1)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def test_ldr_flip_is_flip_evaluators_mean_on_the_displayed_pair():
    # flip-evaluator's own LDR mode on the sRGB-encoded displayed images (its documented input).
    _, expect, _ = flip_evaluator.evaluate(_srgb(REFERENCE).astype(np.float32), _srgb(IMAGE).astype(np.float32),
                                           "LDR")
    m = metrics.image_metrics(IMAGE, REFERENCE, MASK, perceptual=True)
    assert m["flip_ldr"] == pytest.approx(expect, abs=1e-5)
    assert metrics.flip(IMAGE, REFERENCE) == pytest.approx(expect, abs=1e-5)
    assert 0.01 < m["flip_ldr"] < 1


def test_hdr_flip_is_flip_evaluators_mean_and_takes_the_reference_as_reference():
    _, expect, _ = flip_evaluator.evaluate(REFERENCE.astype(np.float32), IMAGE.astype(np.float32), "HDR")
    _, swapped, _ = flip_evaluator.evaluate(IMAGE.astype(np.float32), REFERENCE.astype(np.float32), "HDR")
    assert abs(expect - swapped) > 1e-4  # HDR-FLIP's exposure range comes from the reference
    m = metrics.image_metrics(IMAGE, REFERENCE, MASK, perceptual=True)
    assert m["flip_hdr"] == pytest.approx(expect, abs=1e-6)
    assert m["flip_hdr"] != pytest.approx(m["flip_ldr"], abs=1e-3)


def test_flip_over_the_reflective_pixels_is_the_maps_mean_there():
    error, _, _ = flip_evaluator.evaluate(REFERENCE.astype(np.float32), IMAGE.astype(np.float32), "HDR",
                                          applyMagma=False)
    m = metrics.image_metrics(IMAGE, REFERENCE, MASK, perceptual=True)
    assert m["flip_hdr_reflective"] == pytest.approx(float(error[..., 0][MASK].mean()), abs=1e-6)


def test_ssim_is_scikit_images_on_the_displayed_pair():
    expect = skm.structural_similarity(_srgb(IMAGE), _srgb(REFERENCE), channel_axis=2, data_range=1.0,
                                       gaussian_weights=True, sigma=1.5, use_sample_covariance=False)
    m = metrics.image_metrics(IMAGE, REFERENCE, MASK, perceptual=True)
    assert m["ssim"] == pytest.approx(expect, abs=1e-6)
    assert 0 < m["ssim"] < 0.999
    assert metrics.ssim(REFERENCE, REFERENCE) == pytest.approx(1.0)
    assert metrics.flip(REFERENCE, REFERENCE, dynamic_range="hdr") == 0.0
    # Over a mask: the mean of the SSIM map there, inside the border the window covers.
    _, full = skm.structural_similarity(_srgb(IMAGE), _srgb(REFERENCE), channel_axis=2, data_range=1.0,
                                        gaussian_weights=True, sigma=1.5, use_sample_covariance=False, full=True)
    inner = np.zeros(MASK.shape, bool)
    inner[5:-5, 5:-5] = True
    assert m["ssim_reflective"] == pytest.approx(full.mean(axis=2)[MASK & inner].mean(), abs=1e-6)


def test_small_images_have_no_ssim_and_bad_ranges_are_named():
    small = metrics.image_metrics(IMAGE[:8, :8], REFERENCE[:8, :8], MASK[:8, :8], perceptual=True)
    assert small["ssim"] is None and small["flip_ldr"] is not None
    with pytest.raises(ValueError, match="dynamic_range"):
        metrics.flip(IMAGE, REFERENCE, dynamic_range="hdr10")


def test_missing_package_names_the_extra(monkeypatch):
    import builtins

    real = builtins.__import__

    def no_flip(name, *a, **k):
        if name == "flip_evaluator":
            raise ImportError("No module named 'flip_evaluator'")
        return real(name, *a, **k)

    monkeypatch.setattr(builtins, "__import__", no_flip)
    with pytest.raises(ImportError, match=r"ssrlab\[metrics\]"):
        metrics.flip(IMAGE, REFERENCE)
    with pytest.raises(ImportError, match=r"ssrlab\[metrics\]"):
        metrics.image_metrics(IMAGE, REFERENCE, MASK, perceptual=True)
    assert metrics.image_metrics(IMAGE, REFERENCE, MASK, perceptual=False)["flip_ldr"] is None


def test_ssrlab_perceptual_0_leaves_them_out_unless_asked(monkeypatch):
    monkeypatch.setenv("SSRLAB_PERCEPTUAL", "0")
    assert metrics.image_metrics(IMAGE, REFERENCE, MASK)["flip_hdr"] is None
    assert metrics.image_metrics(IMAGE, REFERENCE, MASK, perceptual=True)["flip_hdr"] is not None
    monkeypatch.setenv("SSRLAB_PERCEPTUAL", "1")
    assert metrics.image_metrics(IMAGE, REFERENCE, MASK)["ssim"] is not None


def _row(t, **errors):
    return {"scene": "s", "view": "default", "time_frame_ms": t, **errors}


def test_pareto_front_over_any_metric():
    rows = [_row(1.0, thesis_error=0.5, flip_ldr=0.10, ssim=0.80),
            _row(2.0, thesis_error=0.3, flip_ldr=0.20, ssim=0.90),
            _row(3.0, thesis_error=0.1, flip_ldr=0.05, ssim=0.85)]
    assert bench.pareto_front(rows, error="thesis_error") == rows
    assert bench.pareto_front(rows, error="flip_ldr") == [rows[0], rows[2]]
    # SSIM is a similarity: higher is better, so the slower row with lower SSIM is dominated.
    assert bench.pareto_front(rows, error="ssim") == [rows[0], rows[1]]
    with pytest.raises(ValueError, match="error"):
        bench.pareto_front(rows, error="thesis_error", error_key="rmse")


def test_sweep_rows_and_the_cli_show_flip_and_ssim(tmp_path, monkeypatch):
    import os
    import subprocess
    import sys

    monkeypatch.setenv("SSRLAB_PERCEPTUAL", "1")
    rows = bench.sweep({"layers": [1]}, ["box_stack"], base={"width": 64, "height": 48, "shadow_map_size": 128},
                       repeats=1, warmup=0, reference="converged", reference_rays=4, progress=False,
                       cache_folder=tmp_path / "cache")
    row = rows[0]
    assert 0 < row["flip_ldr"] < 1 and 0 < row["flip_hdr"] < 1 and 0 < row["ssim"] < 1
    assert row["flip_ldr_reflective"] is not None and row["ssim_reflective"] is not None
    env = {**os.environ, "SSRLAB_CACHE": str(tmp_path / "cache"), "SSRLAB_PERCEPTUAL": "1"}
    r = subprocess.run([sys.executable, "-m", "ssrlab", "render", "--scene", "box_stack", "--width", "64",
                        "--height", "48", "--reference", "converged", "--rays", "4", "--out", str(tmp_path / "r")],
                       capture_output=True, text=True, env=env, cwd=tmp_path, timeout=300)
    assert r.returncode == 0, r.stderr
    header = next(line for line in r.stdout.splitlines() if "thesis error" in line)
    assert "LDR-FLIP" in header and "HDR-FLIP" in header and "SSIM" in header
    cells = next(line for line in r.stdout.splitlines() if line.strip().startswith("all pixels")).split()
    assert len(cells) == 2 + 6 and all(c != "-" for c in cells[2:])
