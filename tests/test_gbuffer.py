"""G-buffer contents: normals, materials, coverage, orientation, finiteness."""

import numpy as np
import pytest

import ssrlab
from conftest import assert_finite, small


@pytest.mark.parametrize("scene_name", ["spheres_and_boxes", "box_stack", "hall", "mirror_test"])
def test_normals_are_unit_length_and_outputs_finite(renderer, scene_name):
    scene = ssrlab.scenes.load(scene_name)
    f = renderer.render(scene, settings=small(width=128, height=72, layers=4))
    g = f.gbuffer
    for name in ("depth", "normal", "albedo", "roughness", "metallic", "reflectivity", "lit"):
        assert_finite(getattr(g, name), name)
    assert_finite(f.color, "color")
    n = g.normal[g.coverage]
    assert len(n) > 0
    np.testing.assert_allclose(np.linalg.norm(n, axis=-1), 1.0, atol=2e-3)  # RGBA16F storage


def test_material_values_round_trip(renderer):
    s = ssrlab.Scene()
    mat = ssrlab.Material(base_color=(0.8, 0.2, 0.05), metallic=0.25, roughness=0.6, reflectivity=0.4)
    s.add_plane((0, 0, -3), 100, normal=(0, 0, 1), material=mat)
    cam = ssrlab.Camera(position=(0, 0, 0), target=(0, 0, -1))
    g = renderer.render(s, cam, small()).gbuffer
    # sRGB8 storage of the albedo: about 1/255 relative, worst at the dark end.
    np.testing.assert_allclose(g.albedo[0], np.broadcast_to([0.8, 0.2, 0.05], g.albedo[0].shape), rtol=0.02)
    np.testing.assert_allclose(g.metallic[0], 0.25, atol=1 / 255)
    np.testing.assert_allclose(g.roughness[0], 0.6, atol=1e-3)
    np.testing.assert_allclose(g.reflectivity[0], 0.4, atol=1 / 255)
    # The plane faces the camera: view-space normal +z.
    np.testing.assert_allclose(g.normal[0], np.broadcast_to([0, 0, 1], g.normal[0].shape), atol=1e-3)


def test_row_zero_is_the_top_of_the_image(renderer):
    s = ssrlab.Scene()
    s.add_box((0, 1.0, -5), (20, 1.0, 1.0))  # a bar above the view axis
    cam = ssrlab.Camera(position=(0, 0, 0), target=(0, 0, -1), fov_y=60)
    cov = renderer.render(s, cam, small(width=64, height=64)).gbuffer.coverage[0]
    rows = np.nonzero(cov.any(axis=1))[0]
    assert rows.max() < 32, "an object above the view axis must land in the top half (row 0 = top)"
    # View-space normals: the bar's visible face points at the camera (+z), x right, y up.
    cols = np.nonzero(cov.any(axis=0))[0]
    assert cols.min() == 0 and cols.max() == 63


def test_lighting_shades_every_layer(renderer):
    scene = ssrlab.scenes.spheres_and_boxes(seed=1)
    g = renderer.render(scene, settings=small(layers=3)).gbuffer
    for layer in range(3):
        lit = g.lit[layer][g.coverage[layer]]
        assert len(lit) > 0 and lit.max() > 0.05, f"layer {layer} has no light"
    assert np.all(g.lit[~g.coverage] == 0)


def test_shadow_darkens_the_floor_under_an_object(renderer):
    s = ssrlab.Scene()
    s.add_plane((0, 0, 0), 20, material=ssrlab.Material(base_color=(1, 1, 1), roughness=1.0))
    s.add_box((0, 2, 0), (2, 0.2, 2))
    s.add_light(ssrlab.directional_light((0, -1, 0), intensity=3.0))
    s.ambient = (0, 0, 0)
    cam = ssrlab.Camera(position=(0, 8, 6), target=(0, 0, 0))
    frame = renderer.render(s, cam, small(width=128, height=128))
    lit = frame.gbuffer
    no_shadow = renderer.render(s, cam, small(width=128, height=128, shadow_map_size=0)).gbuffer
    # Floor pixels under the box are in shadow with a shadow map and lit without one.
    floor_normal = frame.view_matrix[:3, :3] @ np.array([0.0, 1.0, 0.0])
    floor = lit.coverage[0] & (np.abs(lit.normal[0] @ floor_normal - 1.0) < 1e-3)
    dark = floor & (lit.lit[0][..., 0] < 0.2)
    assert dark.sum() > 20
    assert np.all(no_shadow.lit[0][dark][:, 0] > 0.5)
