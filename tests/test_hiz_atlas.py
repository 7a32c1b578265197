"""The Hi-Z tracer's own copy of the pyramid ("hiz_trace", shaders/lib/hiz_atlas.glsl):
every level of the min-max pyramid in one image, texels (min s, slab back s). The tracer's hits are
checked elsewhere (test_tracing); here, that each level lies where the layout says, holds the
pyramid's min exactly, and the back of the slab behind the pyramid's max."""

import numpy as np
import pytest

import ssrlab
from conftest import small

EMPTY = 1e30


def _origin(level, w, h):
    return (0, 0) if level == 0 else (w, h - (h >> (level - 1)) + level - 1)


@pytest.mark.parametrize("use_max", [True, False])
def test_atlas_holds_every_level_min_and_slab_back(renderer, use_max):
    w, h, layers = 77, 45, 2  # odd sizes at several levels
    s = small(width=w, height=h, layers=layers, method="hiz", skip=False, hiz_use_max=use_max)
    f = renderer.render(ssrlab.scenes.spheres_and_boxes(), settings=s)
    levels = int(np.floor(np.log2(max(w, h)))) + 1
    atlas = f.read("hiz_trace")[:, ::-1, :, :2]  # GL row order, as the shader addresses it
    assert atlas.shape[:3] == (layers, h + levels, w + max(w >> 1, 1))
    p = f.projection_matrix.astype(np.float64)

    def slab_back(sd):  # screen depth `thickness` behind screen depth sd (standard depth)
        z = p[2, 3] / ((2.0 * sd - 1.0) + p[2, 2]) + s.thickness
        return ((-p[2, 2] * z + p[2, 3]) / z) * 0.5 + 0.5

    used = np.zeros(atlas.shape[1:3], bool)
    for level in range(levels):
        lw, lh = max(w >> level, 1), max(h >> level, 1)
        ox, oy = _origin(level, w, h)
        assert ox + lw <= atlas.shape[2] and oy + lh <= atlas.shape[1]
        assert not used[oy:oy + lh, ox:ox + lw].any(), f"level {level} overlaps a finer one"
        used[oy:oy + lh, ox:ox + lw] = True
        pyramid = f.read("hiz", level)[:, ::-1, :, :2].astype(np.float64)
        got = atlas[:, oy:oy + lh, ox:ox + lw].astype(np.float64)
        covered = pyramid[..., 0] <= pyramid[..., 1]
        assert covered.any() and (level > 0 or (~covered).any())  # level 0 has empty cells too
        assert np.array_equal(got[..., 0][covered], pyramid[..., 0][covered])
        assert np.all(got[..., 0][~covered] >= EMPTY * 0.99), "an empty cell's min is the empty marker"
        back = got[..., 1][covered]
        if use_max or level == 0:
            want = slab_back(pyramid[..., 1][covered])
            assert np.all(back >= pyramid[..., 1][covered]), "the slab's back lies behind its max"
            np.testing.assert_allclose(back, want, rtol=0, atol=2e-5)
        else:
            assert np.all(back >= EMPTY * 0.99), "a min-only Hi-Z's coarse slab reaches to infinity"
