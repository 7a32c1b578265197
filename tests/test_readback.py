"""Readback (frame overheads): float textures (the colour and the rays RGBA32F, lit and
the normals RGBA16F, depths R32F, the Hi-Z pyramid RG32F) are downloaded as stored, rows put top
first by the driver (GL_MESA_pack_invert) or on the CPU; normalised, sRGB and depth formats go through the readback copy pass. Both must give the
same orientation (row 0 = top) and values."""

import numpy as np
import pytest

import ssrlab
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
