"""Screen-space tracing over deep G-buffers: linear (McGuire-Mara) and Hi-Z (seed 002)."""

import numpy as np
import pytest

import ssrlab
from ssrlab.analytic import mirror_test_hits, pixel_rays, project, ray_box_entry
from conftest import assert_finite, small


@pytest.mark.parametrize("method", ["linear", "hiz"])
@pytest.mark.parametrize("size", [(160, 90), (97, 61)])  # an odd size exercises odd Hi-Z levels
def test_mirror_hits_match_the_analytic_mirror_point(renderer, method, size):
    w, h = size
    f = renderer.render(ssrlab.scenes.mirror_test(), settings=small(width=w, height=h, method=method,
                                                                    sampling="mirror", stride=1))
    expected, ok = mirror_test_hits(f)
    g = f.gbuffer
    ok &= g.coverage[0] & (g.reflectivity[0] > 0.5)  # origin on the mirror
    # "On screen": the pixel holding the true hit shows the wall (not a background pixel
    # whose centre misses the wall's edge).
    col = np.clip(np.nan_to_num(expected[..., 0]).astype(int), 0, w - 1)
    row = np.clip(np.nan_to_num(expected[..., 1]).astype(int), 0, h - 1)
    ok &= g.coverage[0][row, col] & (g.reflectivity[0][row, col] < 0.5)
    assert ok.sum() > 0.2 * w * h / 2
    rays = f.rays
    err = np.linalg.norm(rays.hit_pixel[0] - expected, axis=-1)
    good = ok & rays.hit[0] & (err <= 0.5)
    assert good.sum() >= 0.99 * ok.sum(), f"{good.sum()} of {ok.sum()} within 0.5 px"
    assert np.median(err[ok & rays.hit[0]]) < 0.1


def floating_box():
    """Seed 000, Figs. 1.1 and 1.2: a box floating above a mirror floor. The camera looks down
    on it and cannot see its bottom face; the floor's reflection of that face is what a
    single G-buffer layer cannot provide."""
    s = ssrlab.Scene()
    s.add_plane((0, 0, 0), 20, name="mirror", material=ssrlab.Material(
        base_color=(1, 1, 1), metallic=1.0, roughness=0.0, reflectivity=1.0))
    s.add_box((0, 1.5, 0), (1.0, 1.0, 1.0), name="box", material=ssrlab.Material(base_color=(0.9, 0.3, 0.1)))
    s.add_light(ssrlab.directional_light((0.3, -1.0, -0.4), cast_shadow=False))
    cam = ssrlab.Camera(position=(0, 2.6, 5.0), target=(0, 0.8, 0.0), fov_y=40, near=0.1, far=40)
    return s, cam


@pytest.mark.parametrize("method", ["linear", "hiz"])
def test_hidden_bottom_face_needs_a_second_layer(renderer, method):
    scene, cam = floating_box()
    frames = {layers: renderer.render(scene, cam, small(width=128, height=96, layers=layers, method=method,
                                                        sampling="mirror", thickness=0.2))
              for layers in (1, 2, 4)}
    f = frames[1]
    # Mirror pixels whose reflected ray, analytically, enters the box through its bottom face.
    origin, d = pixel_rays(f)
    p = origin + d * (-origin[1] / d[..., 1])[..., None]
    r = d * np.array([1.0, -1.0, 1.0])
    t_box, axis = ray_box_entry(p, r, np.array([-0.5, 1.0, -0.5]), np.array([0.5, 2.0, 0.5]))
    entry = p + r * np.where(np.isfinite(t_box), t_box, 0)[..., None]
    # Entry points well behind the front face (z = 0.5): farther than the 0.2 thickness, so
    # no tolerance lets a single layer's front face stand in for the bottom face.
    bottom = f.gbuffer.coverage[0] & (f.gbuffer.reflectivity[0] > 0.5) & (d[..., 1] < 0) & np.isfinite(t_box) \
        & (axis == 1) & (entry[..., 2] < 0.5 - 2 * 0.2)
    assert bottom.sum() > 30
    one = frames[1].rays.hit_layer[0][bottom]
    assert (one == 0).mean() > 0.95, "with one layer the bottom face is not there to hit"
    bottom_normal = f.view_matrix[:3, :3] @ np.array([0.0, -1.0, 0.0])  # the face's normal, view space
    for layers in (2, 4):
        frame = frames[layers]
        rays = frame.rays
        layer = rays.hit_layer[0][bottom]
        assert (layer >= 2).mean() > 0.95, f"{layers} layers: the bottom face is in layer 2"
        # The surface at the hit is the bottom face (seen from the camera's side the ray meets
        # its thickness slab up to a few pixels before the 3D crossing, so compare surfaces).
        px = np.floor(rays.hit_pixel[0][bottom]).astype(int)
        n = frame.gbuffer.normal[np.maximum(layer - 1, 0), px[:, 1], px[:, 0]]
        assert (n @ bottom_normal > 0.99).mean() > 0.95


@pytest.mark.parametrize("layers", [1, 4])
def test_linear_and_hiz_agree_on_hit_or_miss(renderer, layers):
    scene = ssrlab.scenes.spheres_and_boxes()
    kw = dict(width=200, height=112, layers=layers, rays_per_pixel=2, stride=1)
    lin = renderer.render(scene, settings=small(method="linear", **kw)).rays
    hiz = renderer.render(scene, settings=small(method="hiz", **kw)).rays
    np.testing.assert_array_equal(lin.direction, hiz.direction)  # the same rays
    traced = np.broadcast_to(lin.traced, lin.hit.shape) & (lin.weight > 0)
    assert traced.sum() > 5000
    agree = (lin.hit == hiz.hit)[traced].mean()
    assert agree >= 0.99, agree
    both = traced & lin.hit & hiz.hit
    assert (lin.hit_layer == hiz.hit_layer)[both].mean() >= 0.98


@pytest.mark.parametrize("method", ["linear", "hiz"])
def test_deeper_layers_are_found(renderer, method):
    rays = renderer.render(ssrlab.scenes.box_stack(), settings=small(width=160, height=96, layers=4,
                                                                     method=method)).rays
    layers = rays.hit_layer[rays.hit]
    assert (layers >= 2).sum() > 50, np.bincount(layers)


def test_hiz_without_the_max_pyramid_finds_the_same_hits_at_more_cost(renderer):
    scene = ssrlab.scenes.box_stack()
    kw = dict(width=160, height=96, layers=3, method="hiz")
    with_max = renderer.render(scene, settings=small(hiz_use_max=True, **kw)).rays
    min_only = renderer.render(scene, settings=small(hiz_use_max=False, **kw)).rays
    same = (with_max.hit_layer == min_only.hit_layer)[np.broadcast_to(with_max.traced, with_max.hit.shape)]
    assert same.mean() > 0.995
    assert min_only.mean_fetches() > with_max.mean_fetches()


def test_hiz_pyramid_is_the_min_max_of_its_cells(renderer):
    w, h = 77, 45  # odd sizes at several levels
    f = renderer.render(ssrlab.scenes.spheres_and_boxes(), settings=small(width=w, height=h, layers=2, method="hiz"))
    g = f.gbuffer
    s = np.where(g.coverage, g.window_depth, np.nan)[:, ::-1]  # GL row order for cell arithmetic
    level, size = 0, np.array([w, h])
    while True:
        lw, lh = max(w >> level, 1), max(h >> level, 1)
        got = f.read("hiz", level)[:, ::-1, :, :2]
        assert got.shape[1:3] == (lh, lw)
        ys, xs = np.arange(h), np.arange(w)
        cy, cx = np.minimum(ys >> level, lh - 1), np.minimum(xs >> level, lw - 1)
        for layer in range(2):
            for y in range(lh):
                for x in range(lw):
                    cell = s[layer][np.ix_(cy == y, cx == x)]
                    cell = cell[np.isfinite(cell)]
                    if cell.size:
                        assert got[layer, y, x, 0] == cell.min() and got[layer, y, x, 1] == cell.max()
                    else:
                        assert got[layer, y, x, 0] > got[layer, y, x, 1]  # empty marker
        if lw == 1 and lh == 1:
            break
        level += 1


def test_stride_trades_fetches(renderer):
    scene = ssrlab.scenes.hall()
    fetches = [renderer.render(scene, settings=small(width=160, height=90, stride=k)).rays.mean_fetches()
               for k in (1, 2, 4, 8)]
    assert all(a > b for a, b in zip(fetches, fetches[1:])), fetches


@pytest.mark.parametrize("scene_name", list(ssrlab.scenes.SCENES))
@pytest.mark.parametrize("method", ["linear", "hiz"])
def test_no_nan_or_inf_anywhere(renderer, scene_name, method):
    scene = ssrlab.scenes.load(scene_name)
    for kw in (dict(layers=2, rays_per_pixel=3, sampling="ggx"),
               dict(layers=1, rays_per_pixel=2, sampling="vndf", downscale=2, depth_mode="reversed_z"),
               dict(layers=3, sampling="ggx_thesis_literal", noise="thesis_hash", stride=4, refine_steps=3,
                    thickness_mode="ray_step", downscale=4, reuse_radius=2, composite="pbr")):
        f = renderer.render(scene, settings=small(width=96, height=64, method=method, **kw))
        assert_finite(f.color, "color")
        assert_finite(f.reflection, "reflection")
        if "rays.hit" in f.texture_names:
            for name in ("hit_uv", "weight", "pdf", "steps", "fade", "direction"):
                assert_finite(getattr(f.rays, name), name)


def test_reversed_z_traces_the_same_hits(renderer):
    scene = ssrlab.scenes.mirror_test()
    for method in ("linear", "hiz"):
        a = renderer.render(scene, settings=small(method=method, sampling="mirror")).rays
        b = renderer.render(scene, settings=small(method=method, sampling="mirror", depth_mode="reversed_z")).rays
        assert (a.hit == b.hit).mean() > 0.995
        both = a.hit & b.hit
        assert np.abs(a.hit_pixel - b.hit_pixel)[both].max() < 0.5
