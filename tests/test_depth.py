"""Depth conventions and the thesis's view-space depth reconstruction (seed 000, 2.3.4)."""

import numpy as np
import pytest

import ssrlab
from conftest import small

NEAR, FAR = 0.1, 100.0


def thesis_view_depth(d: np.ndarray, n: float, f: float) -> np.ndarray:
    """The thesis's formula, z = 2fn / (z_s (f - n) - (f + n)) with z_s = 2d - 1, as positive depth."""
    zs = 2.0 * d.astype(np.float64) - 1.0
    return -(2.0 * f * n) / (zs * (f - n) - (f + n))


def plane_at(distance: float) -> tuple[ssrlab.Scene, ssrlab.Camera]:
    s = ssrlab.Scene()
    s.add_plane((0, 0, -distance), (1000, 1000), normal=(0, 0, 1))
    cam = ssrlab.Camera(position=(0, 0, 0), target=(0, 0, -1), fov_y=60, near=NEAR, far=FAR)
    return s, cam


@pytest.mark.parametrize("distance", [0.35, 5.0, 37.5, 92.0])
def test_thesis_formula_recovers_plane_distance(renderer, distance):
    scene, cam = plane_at(distance)
    f = renderer.render(scene, cam, small())
    d = f.gbuffer.window_depth[0]
    z = thesis_view_depth(d, NEAR, FAR)
    assert np.all(f.gbuffer.coverage[0])
    np.testing.assert_allclose(z, distance, rtol=1e-4)
    # The GPU's linearisation is the same formula.
    np.testing.assert_allclose(f.gbuffer.depth[0], distance, rtol=1e-4)


@pytest.mark.parametrize("distance", [0.35, 5.0, 92.0])
def test_reversed_z_gives_the_same_view_depth(renderer, distance):
    scene, cam = plane_at(distance)
    std = renderer.render(scene, cam, small(depth_mode="standard")).gbuffer
    rev = renderer.render(scene, cam, small(depth_mode="reversed_z")).gbuffer
    np.testing.assert_allclose(rev.depth[0], distance, rtol=1e-5)
    np.testing.assert_allclose(rev.depth[0], std.depth[0], rtol=1e-4)
    # Reversed-Z stores near -> 1, far -> 0: the mirror image of the standard convention
    # (d_rev = n (f - z) / (z (f - n)) = 1 - d_std), at every distance.
    np.testing.assert_allclose(rev.window_depth[0] + std.window_depth[0], 1.0, atol=1e-5)
    expected = NEAR / (FAR - NEAR) * (FAR / distance - 1.0)
    np.testing.assert_allclose(rev.window_depth[0], expected, rtol=1e-4)


def test_projection_matrix_is_the_thesis_matrix():
    cam = ssrlab.Camera(fov_y=60, near=NEAR, far=FAR)
    p = cam.projection_matrix(16 / 9)
    g = 1 / np.tan(np.radians(30))
    expected = np.array([[g / (16 / 9), 0, 0, 0], [0, g, 0, 0],
                         [0, 0, (FAR + NEAR) / (NEAR - FAR), 2 * FAR * NEAR / (NEAR - FAR)], [0, 0, -1, 0]])
    np.testing.assert_allclose(p, expected, rtol=1e-6)


def test_background_depth_is_the_far_plane(renderer):
    s = ssrlab.Scene()
    s.add_sphere((0, 0, -5), 1.0)
    cam = ssrlab.Camera(position=(0, 0, 0), target=(0, 0, -1), near=NEAR, far=FAR)
    for mode in ("standard", "reversed_z"):
        g = renderer.render(s, cam, small(depth_mode=mode)).gbuffer
        empty = ~g.coverage[0]
        assert empty.any() and (~empty).any()
        np.testing.assert_allclose(g.depth[0][empty], FAR, rtol=1e-5)
