"""Issue 11: the classify pass and the trace over its ray list (Settings.skip), Frame.stats."""

import math

import numpy as np
import pytest

import ssrlab
from ssrlab.metrics import thesis_error
from ssrlab.scene import Camera, Environment, Material, Scene, directional_light
from conftest import small

W, H = 64, 48

CASES = [  # (glossy, sampling, layers, method, rays)
    ("stochastic", "mirror", 1, "linear", 1),
    ("stochastic", "vndf", 4, "hiz", 2),
    ("stochastic", "mirror", 4, "hiz", 1),
    ("stochastic", "vndf", 1, "linear", 2),
]


def _pair(renderer, scene, **kw):
    frames = [renderer.render(scene, settings=small(width=W, height=H, skip=skip, **kw)) for skip in (True, False)]
    return frames


@pytest.mark.parametrize("scene_name", list(ssrlab.scenes.SCENES))
@pytest.mark.parametrize("glossy,sampling,layers,method,rays", CASES)
def test_skip_on_and_off_agree(renderer, scene_name, glossy, sampling, layers, method, rays):
    scene = ssrlab.scenes.load(scene_name)
    on, off = _pair(renderer, scene, glossy=glossy, sampling=sampling, layers=layers, method=method,
                    rays_per_pixel=rays, roughness_cutoff=0.6)
    assert "classify" in on.passes and "classify" not in off.passes
    assert thesis_error(on.color, off.color) <= 1e-3
    assert thesis_error(on.reflection, off.reflection) <= 1e-3
    # Every ray texture is written for every pixel: the untraced ones hold the same "no ray".
    for name in ("rays.hit", "rays.sample", "rays.direction", "lit", "linear_depth"):
        np.testing.assert_array_equal(on.read(name), off.read(name), err_msg=name)
    # The list holds exactly the reflective pixels below the cutoff that face the camera.
    g = off.gbuffer
    listed = g.coverage[0] & (g.reflectivity[0] > 0) & (g.roughness[0] <= 0.6)
    sample = off.read("rays.sample")
    traced_rays = int((sample[..., 0] > 0).sum())  # rays the full-screen trace generated
    assert on.stats["pixels_classified"] == W * H
    assert on.stats["rays_traced"] == traced_rays
    assert on.stats["pixels_traced"] <= int(listed.sum())
    assert on.stats["trace_groups"] == math.ceil(on.stats["pixels_traced"] / 64) * rays


@pytest.mark.parametrize("glossy", ["cone", "blur_mips"])
def test_skip_agrees_for_one_ray_glossy_methods(renderer, glossy):
    scene = ssrlab.scenes.load("spheres_and_boxes")
    on, off = _pair(renderer, scene, glossy=glossy, layers=2, method="hiz")
    assert thesis_error(on.color, off.color) <= 1e-3


@pytest.mark.parametrize("downscale", [2, 4])
def test_skip_agrees_at_reduced_trace_resolution(renderer, downscale):
    scene = ssrlab.scenes.load("hall")
    on, off = _pair(renderer, scene, downscale=downscale, rays_per_pixel=2, layers=2, reuse_radius=1)
    assert on.stats["pixels_classified"] == math.ceil(W / downscale) * math.ceil(H / downscale)
    assert thesis_error(on.color, off.color) <= 1e-3
    np.testing.assert_array_equal(on.read("rays.hit"), off.read("rays.hit"))


def _quad_scene(half_w: float, half_h: float, roughness: float = 0.0) -> Scene:
    """A mirror quad facing a camera that looks straight at it from 5 units, before a matte wall."""
    s = Scene()
    s.name = "quad"

    def quad(z, hw, hh, name, material):
        p = np.float32([(-hw, -hh, z), (hw, -hh, z), (hw, hh, z), (-hw, hh, z)])
        s.add_mesh(p, np.array([(0, 1, 2), (0, 2, 3)]), name=name, normals=np.tile(np.float32([0, 0, 1]), (4, 1)),
                   material=material)

    quad(0.0, half_w, half_h, "mirror", Material(base_color=(1, 1, 1), roughness=roughness, metallic=1.0,
                                                 reflectivity=1.0))
    quad(-3.0, 50.0, 50.0, "wall", Material(base_color=(0.6, 0.5, 0.4), roughness=0.9))
    s.add_light(directional_light((0.2, -0.4, -1.0), intensity=2.0, cast_shadow=False))
    s.environment = Environment.constant((0.1, 0.1, 0.1))
    s.camera = Camera(position=(0.0, 0.0, 5.0), target=(0.0, 0.0, 0.0), fov_y=60.0, near=0.1, far=50.0)
    return s


def _expected_pixels(half_w, half_h, fov_y=60.0, dist=5.0):
    """Pixel centres whose camera ray meets the quad |x| < half_w, |y| < half_h at distance dist."""
    t = math.tan(math.radians(fov_y) / 2)
    xs = ((np.arange(W) + 0.5) / W * 2 - 1) * t * W / H * dist
    ys = ((np.arange(H) + 0.5) / H * 2 - 1) * t * dist
    return int((np.abs(xs) < half_w).sum() * (np.abs(ys) < half_h).sum())


@pytest.mark.parametrize("method", ["linear", "hiz"])
def test_a_known_number_of_reflective_pixels_traces_exactly_that_many(renderer, method):
    # Edges half-way between pixel centres (the pixel pitch at 5 units is 2 t 5 / H).
    pitch = 2 * math.tan(math.radians(30)) * 5 / H
    hw, hh = 9 * pitch, 5 * pitch  # 18 x 10 pixels
    expected = _expected_pixels(hw, hh)
    assert expected == 18 * 10
    f = renderer.render(_quad_scene(hw, hh), settings=small(width=W, height=H, method=method, rays_per_pixel=3,
                                                             sampling="vndf"))
    g = f.gbuffer
    assert int((g.reflectivity[0] > 0).sum()) == expected
    assert f.stats["pixels_classified"] == W * H
    assert f.stats["pixels_traced"] == expected
    assert f.stats["rays_traced"] == 3 * expected
    assert f.stats["trace_groups"] == math.ceil(expected / 64) * 3
    assert f.stats["depth_fetches"] > 0
    # Exactly the listed pixels carry traced rays.
    traced = f.read("rays.sample")[..., 0] > 0
    assert traced.sum() == 3 * expected


def test_an_empty_list_dispatches_no_trace_group(renderer):
    # The only reflective surface is rougher than the cutoff: nothing is listed, nothing traced.
    f = renderer.render(_quad_scene(1.0, 1.0, roughness=0.8),
                        settings=small(width=W, height=H, roughness_cutoff=0.5))
    assert f.stats["pixels_traced"] == 0
    assert f.stats["trace_groups"] == 0
    assert f.stats["rays_traced"] == 0
    assert not (f.read("rays.sample")[..., 0] > 0).any()
    off = renderer.render(_quad_scene(1.0, 1.0, roughness=0.8),
                          settings=small(width=W, height=H, roughness_cutoff=0.5, skip=False))
    assert thesis_error(f.color, off.color) <= 1e-3


def test_facing_threshold_drops_grazing_pixels(renderer):
    scene = ssrlab.scenes.load("mirror_test")
    base = renderer.render(scene, settings=small(width=W, height=H, sampling="mirror"))
    strict = renderer.render(scene, settings=small(width=W, height=H, sampling="mirror", classify_facing=0.9))
    assert 0 <= strict.stats["pixels_traced"] < base.stats["pixels_traced"]
    with pytest.raises(ValueError, match="classify_facing"):
        small(classify_facing=1.5)


def test_stats_count_passes_without_skip(renderer):
    f = renderer.render(ssrlab.scenes.load("mirror_test"), settings=small(width=W, height=H, skip=False))
    assert f.stats == {"passes_run": len(f.passes), "layers_used": 1, "layers_lit": 1}


def test_layers_used_is_the_depth_complexity_of_the_view(renderer):
    # Three parallel quads one behind the other (no back faces): depth complexity 3.
    s = _quad_scene(1.0, 1.0)
    p = np.float32([(-2, -2, -1.5), (2, -2, -1.5), (2, 2, -1.5), (-2, 2, -1.5)])
    s.add_mesh(p, np.array([(0, 1, 2), (0, 2, 3)]), name="middle", normals=np.tile(np.float32([0, 0, 1]), (4, 1)),
               material=Material(base_color=(0.2, 0.5, 0.2), roughness=0.7))
    f = renderer.render(s, settings=small(width=W, height=H, layers=16))
    assert f.stats["layers_used"] == 3
    assert f.layer_samples[2] > 0 and not any(f.layer_samples[3:])
    assert f.stats["layers_lit"] == 3  # the 13 empty layers are cleared, not shaded
    off = renderer.render(s, settings=small(width=W, height=H, layers=16, skip=False))
    assert off.stats["layers_lit"] == 16
    for name in ("lit", "linear_depth"):
        np.testing.assert_array_equal(f.read(name), off.read(name), err_msg=name)
    assert thesis_error(f.color, off.color) <= 1e-3


@pytest.mark.parametrize("skip", [True, False])
def test_adaptive_rays_trace_one_ray_per_mirror_pixel(renderer, skip):
    pitch = 2 * math.tan(math.radians(30)) * 5 / H
    hw, hh = 9 * pitch, 5 * pitch  # 18 x 10 mirror pixels
    kw = dict(width=W, height=H, rays_per_pixel=8, sampling="vndf", skip=skip)
    fixed = renderer.render(_quad_scene(hw, hh), settings=small(**kw))
    adaptive = renderer.render(_quad_scene(hw, hh), settings=small(adaptive_rays=True, **kw))
    per_pixel = (adaptive.read("rays.sample")[..., 0] > 0).sum(axis=0)
    assert per_pixel.max() == 1 and per_pixel.sum() == 180
    assert (fixed.read("rays.sample")[..., 0] > 0).sum() == 8 * 180
    if skip:
        assert adaptive.stats["rays_traced"] == 180 and fixed.stats["rays_traced"] == 8 * 180
    # A mirror's 8 rays all take the mirror direction: one ray gives the same reflection.
    assert thesis_error(adaptive.color, fixed.color) <= 1e-3


def test_adaptive_rays_follow_roughness(renderer):
    pitch = 2 * math.tan(math.radians(30)) * 5 / H
    f = renderer.render(_quad_scene(9 * pitch, 5 * pitch, roughness=0.3),
                        settings=small(width=W, height=H, rays_per_pixel=8, adaptive_rays=True))
    per_pixel = (f.read("rays.sample")[..., 0] > 0).sum(axis=0)
    # ceil(8 * 0.3) = 3 rays (a few VNDF samples may come out invalid, weight 0).
    assert per_pixel.max() == 3 and (per_pixel == 3).mean() > 0.9 * 180 / (W * H)
    assert f.stats["rays_traced"] == per_pixel.sum()


def test_a_list_longer_than_a_row_of_groups_is_traced_whole(renderer):
    # 320 x 240 mirror pixels: 1200 groups of 64, more than one row of 1024 (ray_list.glsl).
    kw = dict(width=320, height=240, sampling="mirror", rays_per_pixel=1)
    scene = _quad_scene(100.0, 100.0)
    on = renderer.render(scene, settings=small(**kw))
    off = renderer.render(scene, settings=small(skip=False, **kw))
    assert on.stats["pixels_traced"] == on.stats["rays_traced"] == 320 * 240
    assert on.stats["trace_groups"] == 1024 * 2
    np.testing.assert_array_equal(on.read("rays.sample"), off.read("rays.sample"))
    np.testing.assert_array_equal(on.read("rays.hit"), off.read("rays.hit"))
