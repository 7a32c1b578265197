"""Deep G-buffer by depth peeling (seed 000, 1.5.1 and 2.2)."""

import numpy as np
import pytest

import ssrlab
from conftest import small


def nested_spheres() -> tuple[ssrlab.Scene, ssrlab.Camera]:
    s = ssrlab.Scene()
    for r in (1.0, 2.0, 3.0):
        s.add_sphere((0, 0, 0), r, segments=96)
    cam = ssrlab.Camera(position=(0, 0, 10), target=(0, 0, 0), fov_y=40, near=0.5, far=50)
    return s, cam


@pytest.mark.parametrize("depth_mode", ["standard", "reversed_z"])
def test_ray_through_three_nested_spheres_has_six_layers(renderer, depth_mode):
    scene, cam = nested_spheres()
    f = renderer.render(scene, cam, small(width=65, height=65, layers=8, depth_mode=depth_mode))
    g = f.gbuffer
    cy, cx = 32, 32  # the pixel whose ray runs along the view axis through the centre
    covered = g.coverage[:, cy, cx]
    assert covered.tolist() == [True] * 6 + [False] * 2
    depths = g.depth[:6, cy, cx]
    assert np.all(np.diff(depths) > 0), depths
    # Front and back of radius 3, 2, 1 spheres 10 units away; tessellation moves them very little.
    np.testing.assert_allclose(depths, [7, 8, 9, 11, 12, 13], rtol=2e-3)


def test_back_face_culling_keeps_front_faces_only(renderer):
    scene, cam = nested_spheres()
    g = renderer.render(scene, cam, small(width=65, height=65, layers=8, backface_culling=True)).gbuffer
    assert g.coverage[:, 32, 32].tolist() == [True] * 3 + [False] * 5
    np.testing.assert_allclose(g.depth[:3, 32, 32], [7, 8, 9], rtol=2e-3)


@pytest.mark.parametrize("scene_name", ["spheres_and_boxes", "box_stack", "hall"])
def test_every_layer_is_strictly_behind_the_previous(renderer, scene_name):
    scene = ssrlab.scenes.load(scene_name)
    g = renderer.render(scene, settings=small(width=160, height=90, layers=6)).gbuffer
    cov, depth = g.coverage, g.depth
    for i in range(1, 6):
        # A layer covers a pixel only where the layer in front does, and lies strictly behind it.
        assert not np.any(cov[i] & ~cov[i - 1]), f"layer {i} covers a pixel layer {i - 1} does not"
        both = cov[i] & cov[i - 1]
        assert np.all(depth[i][both] > depth[i - 1][both]), f"layer {i} not behind layer {i - 1}"
    assert cov[1].any(), "a second layer must exist in this scene"


def test_layers_match_single_layer_render(renderer):
    """Layer 0 of a deep G-buffer is exactly the ordinary G-buffer."""
    scene = ssrlab.scenes.spheres_and_boxes(seed=3)
    one = renderer.render(scene, settings=small(layers=1)).gbuffer
    four = renderer.render(scene, settings=small(layers=4)).gbuffer
    np.testing.assert_array_equal(one.depth[0], four.depth[0])
    np.testing.assert_array_equal(one.lit[0], four.lit[0])


@pytest.mark.parametrize("layers", [0, 17, -1])
def test_layer_count_out_of_range(layers):
    with pytest.raises(ValueError, match="layers"):
        ssrlab.Settings(layers=layers)


def test_empty_layers_are_skipped(renderer):
    """Beyond the first empty layer no geometry is drawn, and the layers read back empty."""
    scene, cam = nested_spheres()
    f = renderer.render(scene, cam, small(width=65, height=65, layers=10))
    samples = f.layer_samples
    assert all(n > 0 for n in samples[:6]) and samples[6:] == [0, 0, 0, 0]
    assert not f.gbuffer.coverage[6:].any()
    # Layer 6 is the first empty one (its draws ran, found nothing); 7+ skip their draws.
    np.testing.assert_array_equal(f.gbuffer.coverage[:6].sum(axis=(1, 2)) > 0, True)
