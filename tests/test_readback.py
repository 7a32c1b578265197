"""Readback (frame overheads): float textures (the colour and the rays RGBA32F, lit and
the normals RGBA16F, depths R32F, the Hi-Z pyramid RG32F) are downloaded as stored, rows put top
first by the driver (GL_MESA_pack_invert) or on the CPU; normalised, sRGB and depth formats go through the readback copy pass. Both must give the
same orientation (row 0 = top) and values."""

import numpy as np
import pytest

import ssrlab
from ssrlab import display
from conftest import small


@pytest.mark.parametrize("size", [(96, 64), (37, 23)])
def test_colour_equals_lit_where_nothing_reflects(renderer, size):
    # Linear composite: a covered pixel that does not reflect is its lit colour, exactly (RGBA16F
    # lit) in the final colour (RGBA32F); both downloaded, the mask from the RGBA8 material (copy
    # pass), and lit's alpha (0 where nothing is) against the material's coverage.
    w, h = size
    f = renderer.render(ssrlab.scenes.spheres_and_boxes(seed=1), settings=small(width=w, height=h))
    lit = f.gbuffer.lit[0]
    covered = f.gbuffer.coverage[0]
    assert not np.array_equal(covered, covered[::-1])
    np.testing.assert_array_equal(f.read("lit")[0, ..., 3] > 0.25, covered)
    plain = covered & (f.gbuffer.reflectivity[0] == 0.0)
    assert plain.sum() > w * h // 20 and (~plain).sum() > 0
    np.testing.assert_array_equal(f.color[plain], lit[plain])


def test_every_ray_layer_keeps_its_own_rows(renderer):
    # rays.sample (RGBA32F, 3 layers): each layer's traced flag where the G-buffer (RGBA8, copy
    # pass) holds a reflective surface facing the camera; and an asymmetric image, so that a
    # layer read upside down or from another layer would not match.
    s = small(width=64, height=48, rays_per_pixel=3, skip=False)
    f = renderer.render(ssrlab.scenes.spheres_and_boxes(seed=1), settings=s)
    sample = f.read("rays.sample")
    assert sample.shape == (3, 48, 64, 4)
    reflective = f.gbuffer.coverage[0] & (f.gbuffer.reflectivity[0] > 0.0) & (f.gbuffer.roughness[0] <= s.roughness_cutoff)
    assert not np.array_equal(reflective, reflective[::-1])
    for layer in range(3):
        traced = sample[layer, ..., 3] > 0.5
        assert np.array_equal(traced, reflective & traced)  # never where nothing reflects
        assert traced.sum() >= 0.9 * reflective.sum() > 0  # all but surfaces seen edge-on
    assert renderer.stats["readback_bytes"] > 0


@pytest.mark.parametrize("name", ["color", "lit", "rays.sample", "linear_depth", "gbuffer.albedo", "gbuffer.material",
                                  "gbuffer.depth", "gbuffer.normal"])
def test_staged_readback_equals_download(name):
    # Renderer.readback_path 'staged' (copy pass, DMA into pinned client memory, parallel copy;
    # the GPU default) gives exactly the driver download's values, rows and layers: a frame is
    # read both ways from one renderer (rows of 37 texels: no power-of-two alignment).
    r = ssrlab.Renderer()
    f = r.render(ssrlab.scenes.spheres_and_boxes(seed=1), settings=small(width=37, height=23, layers=2))
    r.readback_path = "download"
    assert r.info["readback_path"] == "download"
    a = f.read(name, cache=False)
    r.readback_path = "staged"
    assert r.info["readback_path"] == "staged"
    b = f.read(name, cache=False)
    assert a.shape == b.shape and a.dtype == b.dtype == np.float32
    np.testing.assert_array_equal(a, b)
    with pytest.raises(ValueError, match="readback_path"):
        r.readback_path = "dma"


def test_read_without_the_cache_downloads_again_and_keeps_nothing(renderer):
    """What benchmarks/timing/readback.py times: Frame.read(cache=False) copies the texture from the GPU
    each time, into a new writable array equal to the cached one, and leaves the cache alone."""
    f = renderer.render(ssrlab.scenes.spheres_and_boxes(seed=1), settings=small(width=64, height=48, rays_per_pixel=2))
    before = renderer.stats["readbacks"]
    a, b = f.read("color", cache=False), f.read("color", cache=False)
    assert renderer.stats["readbacks"] == before + 2
    assert a is not b and a.flags.writeable and np.array_equal(a, b)
    cached = f.read("color")
    assert renderer.stats["readbacks"] == before + 3 and not cached.flags.writeable
    assert np.array_equal(a, cached) and f.read("color") is cached
    # The rays' slots that hold no ray read as zeros either way (skip's ray list).
    np.testing.assert_array_equal(f.read("rays.hit", cache=False), f.read("rays.hit"))
    assert 0 < renderer.scratch_bytes <= renderer.gpu_bytes
    assert ssrlab.io.image_backend() in ("OpenImageIO", "python")


# -- the colour as display bytes (Frame.srgb8) ------------------------------------------------------
def _codes_by_thresholds(x: np.ndarray, exposure: float) -> np.ndarray:
    """A value's code as the count of thresholds at or below it, exposed and clamped as
    ssrlab.io.linear_to_srgb does (what passes/display_bytes.comp computes)."""
    y = np.clip(np.nan_to_num(np.asarray(x, np.float32)) * np.float32(exposure), 0.0, 1.0)
    return np.searchsorted(display.srgb8_thresholds(), y, side="right").astype(np.uint8)


def test_thresholds_are_where_each_code_begins():
    t = display.srgb8_thresholds()
    assert t.dtype == np.float32 and t.shape == (255,) and np.all(np.diff(t) > 0)
    codes = display.to_bytes(display.srgb(t[:, None]))[:, 0]
    before = display.to_bytes(display.srgb(np.nextafter(t, np.float32(0))[:, None]))[:, 0]
    np.testing.assert_array_equal(codes, np.arange(1, 256))
    np.testing.assert_array_equal(before, np.arange(0, 255))


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")  # numpy at exposure 1e30
@pytest.mark.parametrize("exposure", [0.0, 0.37, 1.0, 3.3, 1e30])
def test_codes_counted_by_thresholds_equal_the_transfer_function(exposure):
    rng = np.random.default_rng(3)
    t = display.srgb8_thresholds()
    near = (t.view(np.int32)[:, None] + np.arange(-3, 4, dtype=np.int32)).view(np.float32).ravel()
    x = np.concatenate([near / np.float32(exposure) if exposure > 0 else near,
                        (rng.random(20000, np.float32) ** 3) * 2.0 - 0.1,
                        np.linspace(0, 1, 100001, dtype=np.float32),
                        np.array([np.nan, np.inf, -np.inf, -0.0, 3.4e38, -3.4e38, 1e-45], np.float32)])
    x = np.resize(x, (1, x.size, 3))
    np.testing.assert_array_equal(_codes_by_thresholds(x, exposure), display.to_bytes(display.srgb(x, exposure)))


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")  # numpy at exposure 1e30
@pytest.mark.parametrize("scene, size", [("hall", (96, 54)), ("spheres_and_boxes", (37, 23))])
@pytest.mark.parametrize("exposure", [0.0, 0.37, 1.0, 17.0, 1e30])
def test_srgb8_is_the_colour_as_displayed_code_for_code(renderer, scene, size, exposure):
    # 37 x 23 pixels: not a whole number of the shader's four-pixel words
    sc = ssrlab.scenes.load(scene)
    f = renderer.render(sc, settings=small(width=size[0], height=size[1]))
    got = f.srgb8(exposure)
    assert got.dtype == np.uint8 and got.shape == (size[1], size[0], 3)
    np.testing.assert_array_equal(got, display.to_bytes(display.srgb(f.color, exposure)))
    if exposure == 1.0:
        assert len(np.unique(got)) > 20  # a picture, not a constant


def test_srgb8_of_the_anti_aliased_colour_and_bad_input(renderer):
    sc = ssrlab.scenes.load("hall")
    f = renderer.render(sc, settings=small(width=64, height=36, taa="clamped"))
    assert "color.taa" in f.texture_names
    np.testing.assert_array_equal(f.srgb8(), display.to_bytes(display.srgb(f.color)))
    with pytest.raises(ValueError, match="exposure"):
        f.srgb8(float("nan"))
    f.release()
    with pytest.raises(ValueError, match="released"):
        f.srgb8()
