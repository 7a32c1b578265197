"""Image error metrics against values worked out by hand on tiny images."""

import math

import numpy as np
import pytest

from ssrlab import metrics

# A 2x2 RGB image and its reference. Per pixel, |image - reference| by channel:
#   (0, 0): 0, 0, 0        -> sum 0,     squares 0
#   (0, 1): 1, 0, 0        -> sum 1,     squares 1
#   (1, 0): 0.25, 0, 0.5   -> sum 0.75,  squares 0.0625 + 0.25 = 0.3125
#   (1, 1): 0, 0, 1        -> sum 1,     squares 1
IMAGE = np.array([[[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]],
                  [[0.5, 0.25, 0.0], [0.0, 0.0, 1.0]]], dtype=np.float32)
REFERENCE = np.array([[[0.0, 0.0, 0.0], [0.0, 1.0, 1.0]],
                      [[0.25, 0.25, 0.5], [0.0, 0.0, 0.0]]], dtype=np.float32)
# The anti-diagonal pixels (0, 1) and (1, 0).
MASK = np.array([[False, True], [True, False]])


def test_thesis_error_by_hand():
    # (0 + 1 + 0.75 + 1) / 4 pixels
    assert metrics.thesis_error(IMAGE, REFERENCE) == pytest.approx(2.75 / 4, abs=1e-12)
    # (1 + 0.75) / 2 pixels
    assert metrics.thesis_error(IMAGE, REFERENCE, MASK) == pytest.approx(1.75 / 2, abs=1e-12)


def test_rmse_and_psnr_by_hand():
    # Squares sum to 2.3125 over 4 pixels x 3 channels = 12 values.
    mse = 2.3125 / 12
    assert metrics.rmse(IMAGE, REFERENCE) == pytest.approx(math.sqrt(mse), abs=1e-12)
    assert metrics.psnr(IMAGE, REFERENCE) == pytest.approx(10 * math.log10(1 / mse), abs=1e-9)
    assert metrics.psnr(IMAGE, REFERENCE, peak=2.0) == pytest.approx(10 * math.log10(4 / mse), abs=1e-9)
    # Masked: (1 + 0.3125) over 2 pixels x 3 channels.
    masked_mse = 1.3125 / 6
    assert metrics.rmse(IMAGE, REFERENCE, MASK) == pytest.approx(math.sqrt(masked_mse), abs=1e-12)
    assert metrics.psnr(IMAGE, REFERENCE, MASK) == pytest.approx(10 * math.log10(1 / masked_mse), abs=1e-9)


def test_error_image_by_hand():
    e = metrics.error_image(IMAGE, REFERENCE)
    assert e.dtype == np.float32 and e.shape == (2, 2)
    np.testing.assert_array_equal(e, np.array([[0.0, 1.0], [0.75, 1.0]], np.float32))


def test_identical_images_have_zero_error_and_capped_psnr():
    assert metrics.thesis_error(IMAGE, IMAGE) == 0.0
    assert metrics.rmse(IMAGE, IMAGE) == 0.0
    p = metrics.psnr(IMAGE, IMAGE)
    assert p == metrics.PSNR_CAP_DB and math.isfinite(p)
    # A difference far below the cap's RMSE is capped too, never above it.
    assert metrics.psnr(IMAGE + np.float32(1e-7), IMAGE) == metrics.PSNR_CAP_DB


def test_the_error_does_not_depend_on_the_order_of_the_arguments_or_the_dtype():
    assert metrics.thesis_error(REFERENCE, IMAGE) == metrics.thesis_error(IMAGE, REFERENCE)
    as64 = metrics.thesis_error(IMAGE.astype(np.float64), REFERENCE.astype(np.float64))
    assert metrics.thesis_error(IMAGE, REFERENCE) == as64


def test_float32_inputs_are_accumulated_in_float64():
    # In float32, 2^24 + 1 rounds back to 2^24, so a float32 sum of (2^24, 1, 1) is 2^24.
    a = np.array([[[2.0**24, 1.0, 1.0]]], np.float32)
    b = np.zeros_like(a)
    assert metrics.thesis_error(a, b) == 2.0**24 + 2
    assert isinstance(metrics.thesis_error(a, b), float)


def test_image_metrics_whole_and_reflective():
    m = metrics.image_metrics(IMAGE, REFERENCE, MASK)
    assert set(m) == set(metrics.METRIC_KEYS)
    assert m["thesis_error"] == pytest.approx(2.75 / 4)
    assert m["thesis_error_reflective"] == pytest.approx(1.75 / 2)
    assert m["rmse"] == pytest.approx(math.sqrt(2.3125 / 12))
    assert m["rmse_reflective"] == pytest.approx(math.sqrt(1.3125 / 6))
    assert m["psnr_reflective"] == pytest.approx(10 * math.log10(6 / 1.3125))
    empty = metrics.image_metrics(IMAGE, REFERENCE, np.zeros((2, 2), bool))
    assert empty["thesis_error"] == m["thesis_error"]
    assert empty["thesis_error_reflective"] is None and empty["psnr_reflective"] is None


def test_error_image_mean_is_the_thesis_error():
    rng = np.random.default_rng(3)
    a, b = rng.uniform(0, 2, (5, 7, 3)), rng.uniform(0, 2, (5, 7, 3))
    assert metrics.error_image(a, b).mean(dtype=np.float64) == pytest.approx(metrics.thesis_error(a, b), rel=1e-6)


@pytest.mark.parametrize("call, match", [
    (lambda: metrics.thesis_error(IMAGE, REFERENCE[:1]), "same shape"),
    (lambda: metrics.thesis_error(IMAGE[..., 0], REFERENCE[..., 0]), "image must be a non-empty"),
    (lambda: metrics.rmse(IMAGE, "not an image"), "reference must be a numeric"),
    (lambda: metrics.thesis_error(IMAGE, REFERENCE, MASK[:1]), "mask must have the image's"),
    (lambda: metrics.thesis_error(IMAGE, REFERENCE, MASK.astype(np.uint8)), "mask must be a boolean"),
    (lambda: metrics.thesis_error(IMAGE, REFERENCE, np.zeros((2, 2), bool)), "mask selects no pixel"),
    (lambda: metrics.psnr(IMAGE, REFERENCE, peak=0.0), "peak"),
    (lambda: metrics.image_metrics(IMAGE, REFERENCE, MASK[0]), "reflective_mask"),
    (lambda: metrics.error_image(np.zeros((0, 2, 3)), np.zeros((0, 2, 3))), "image must be a non-empty"),
])
def test_bad_input_raises_naming_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_nan_and_inf_are_rejected(bad):
    broken = IMAGE.copy()
    broken[1, 0, 2] = bad
    with pytest.raises(ValueError, match="image contains 1 NaN/Inf"):
        metrics.thesis_error(broken, REFERENCE)
    with pytest.raises(ValueError, match="reference contains 1 NaN/Inf"):
        metrics.psnr(IMAGE, broken)
