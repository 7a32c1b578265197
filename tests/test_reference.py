"""Ground truth: rays traced against the triangles (GPU BVH, checked against Embree),
shaded by the G-buffer's own shading code."""

import numpy as np
import pytest

import ssrlab
from ssrlab.analytic import ggx_shade, mirror_test_hits, pixel_rays
from conftest import assert_finite, model_path, small
from ssrlab.scenes import MIRROR_COLORS, MIRROR_TILE, MIRROR_TILES, MIRROR_WALL_Z
from test_tracing import floating_box


@pytest.mark.parametrize("viewer", ["camera", "ray"])
def test_converged_reference_is_the_analytic_mirror_image(renderer, viewer):
    scene = ssrlab.scenes.mirror_test()
    f = renderer.render(scene, settings=small(width=160, height=90))
    ref = f.reference("converged", rays=1, viewer=viewer)
    cam, d = pixel_rays(f)
    _, ok = mirror_test_hits(f)
    g = f.gbuffer
    floor = ok & g.coverage[0] & (g.reflectivity[0] > 0.5)
    # The mirror point on the wall, its tile colour, and its shading by the documented model.
    p = cam + d * (-cam[1] / d[..., 1])[..., None]
    # Rays leave the floor from the exact point where the camera ray meets it (no origin_bias).
    r = d * np.array([1.0, -1.0, 1.0])
    h = p + r * ((MIRROR_WALL_Z - p[..., 2]) / r[..., 2])[..., None]
    half = MIRROR_TILES * MIRROR_TILE / 2
    i = np.floor((h[..., 0] + half) / MIRROR_TILE).astype(int)
    j = np.floor(h[..., 1] / MIRROR_TILE).astype(int)
    # Away from tile edges, where a tile's colour is unambiguous.
    fx, fy = (h[..., 0] + half) / MIRROR_TILE % 1, h[..., 1] / MIRROR_TILE % 1
    floor &= (np.minimum(fx, 1 - fx) > 1e-3) & (np.minimum(fy, 1 - fy) > 1e-3)
    albedo = np.where(((i + j) % 2 == 0)[..., None], MIRROR_COLORS[0], MIRROR_COLORS[1])
    light = scene.lights[0]
    viewer_pos = cam if viewer == "camera" else p
    expected = ggx_shade(albedo, 0.0, 0.9, np.broadcast_to([0.0, 0.0, 1.0], h.shape), viewer_pos - h,
                         [(light.direction, np.array(light.color) * light.intensity)], scene.ambient)
    assert floor.sum() > 1000
    np.testing.assert_allclose(ref.reflection[floor], expected[floor], atol=1e-3)
    # The composite with a mirror of reflectivity 1 is the reflection itself.
    np.testing.assert_allclose(ref.color[floor], ref.reflection[floor], atol=1e-6)


def _embree_truth(scene, f, truth):
    """The frame's reflection rays, from the per-ray reference's origins, traced on the CPU by
    Embree: (traced mask, the GPU reference's hits, Embree's hits, Embree's result)."""
    rays = f.rays
    traced = np.broadcast_to(rays.traced, rays.hit.shape) & (rays.weight > 0)
    # The same world-space rays on the CPU with Embree.
    s = f.settings
    inv_view = np.linalg.inv(f.view_matrix.astype(np.float64))
    R, h, w = rays.hit.shape
    qy, qx = np.meshgrid(np.arange(h), np.arange(w), indexing="ij")
    z = f.gbuffer.depth[0]
    P = f.projection_matrix
    ndc = np.stack([(qx + 0.5) / s.width * 2 - 1, 1 - (qy + 0.5) / s.height * 2], -1)
    pos = np.stack([ndc[..., 0] * z / P[0, 0], ndc[..., 1] * z / P[1, 1], -z], -1)
    origin = pos + f.gbuffer.normal[0] * (s.origin_bias * z)[..., None]
    o_world = origin @ inv_view[:3, :3].T + inv_view[:3, 3]
    # The reference leaves the exact surface point (the camera ray's hit, moved off by a few
    # ulps) where the camera ray meets the G-buffer's object, else SSR's biased origin; here the
    # camera rays' Embree hits, and a t_min of 1e-4 for the ulp offset.
    cam = np.broadcast_to(inv_view[:3, 3], pos.shape)
    pix = np.stack([ndc[..., 0] / P[0, 0], ndc[..., 1] / P[1, 1], -np.ones_like(z)], -1) @ inv_view[:3, :3].T
    pix /= np.linalg.norm(pix, axis=-1, keepdims=True)
    primary = ssrlab._core.embree_intersect(scene, cam.reshape(-1, 3).astype(np.float32),
                                            pix.reshape(-1, 3).astype(np.float32), 0.0, np.inf)
    exact = (np.isfinite(primary["t"]) & (primary["object"] == f.gbuffer.object_id[0].ravel())).reshape(h, w)
    t_cam = np.where(np.isfinite(primary["t"]), primary["t"], 0.0).reshape(h, w)
    o_world = np.where(exact[..., None], cam + pix * t_cam[..., None], o_world)
    d_world = rays.direction.astype(np.float64) @ inv_view[:3, :3].T
    with np.errstate(invalid="ignore"):  # untraced slots hold a zero direction
        d_world /= np.linalg.norm(d_world, axis=-1, keepdims=True)
    o = np.broadcast_to(o_world, d_world.shape)[traced]
    # The ulp offset the GPU uses grows with the coordinates: t_min follows the scene's size
    # (1e-4 for a scene ten units across).
    lo, hi = (np.asarray(b, np.float64) for b in scene.bounds)
    t_min = 1e-4 * max(1.0, float(np.linalg.norm(hi - lo)) / 10.0)
    cpu = ssrlab._core.embree_intersect(scene, o.astype(np.float32), d_world[traced].astype(np.float32), t_min,
                                        s.max_distance)
    gpu_hit, cpu_hit = truth.hit[traced], np.isfinite(cpu["t"])
    return traced, gpu_hit, cpu_hit, cpu


def _assert_agrees_with_embree(truth, traced, gpu_hit, cpu_hit, cpu, *, share=0.999, t_rtol=1e-3, t_share=1.0):
    assert (gpu_hit == cpu_hit).mean() > share
    both = gpu_hit & cpu_hit
    assert (truth.object[traced][both] == cpu["object"][both]).mean() > share
    t_gpu, t_cpu = truth.t[traced][both], cpu["t"][both]
    close = np.abs(t_gpu - t_cpu) <= 1e-4 + t_rtol * np.abs(t_cpu)
    assert close.mean() >= t_share, f"{100 * (1 - close.mean()):.2f} % of the hit distances differ"


def test_gpu_reference_hits_agree_with_embree(renderer):
    scene = ssrlab.scenes.spheres_and_boxes(seed=3)
    f = renderer.render(scene, settings=small(width=96, height=64, rays_per_pixel=4, sampling="vndf"))
    truth = f.reference("per_ray")
    traced, gpu_hit, cpu_hit, cpu = _embree_truth(scene, f, truth)
    assert traced.sum() > 3000 and cpu_hit.mean() > 0.2
    _assert_agrees_with_embree(truth, traced, gpu_hit, cpu_hit, cpu)


def test_gpu_reference_on_a_complex_model_agrees_with_embree(renderer):
    scene = ssrlab.scenes.load(str(model_path("2CylinderEngine/2CylinderEngine.glb")))
    for i in range(scene.object_count):
        m = scene.material(i)
        m.reflectivity, m.roughness, m.metallic = 0.8, 0.4, 1.0
        scene.set_material(i, m)
    # Reversed-Z: the model's camera spans near 0.05 to far 1e6, where the standard convention's
    # depths (from which the test rebuilds the rays' origins) are too coarse to start on the surface.
    f = renderer.render(scene, settings=small(width=96, height=72, rays_per_pixel=2, layers=2,
                                              depth_mode="reversed_z"))
    truth = f.reference("per_ray")
    traced, gpu_hit, cpu_hit, cpu = _embree_truth(scene, f, truth)
    assert traced.sum() > 2000 and truth.hit[traced].mean() > 0.3
    assert_finite(truth.radiance[traced], "radiance")
    # Thousands of thin, curved triangles: the GLSL BVH and Embree agree on what each ray hits;
    # the distances agree to 1 % (the test rebuilds the origins from depths of a model hundreds
    # of units across, a millimetre off).
    _assert_agrees_with_embree(truth, traced, gpu_hit, cpu_hit, cpu, share=0.995, t_rtol=1e-2, t_share=0.99)


@pytest.mark.parametrize("method", ["linear", "hiz"])
def test_per_ray_coverage_on_the_mirror(renderer, method):
    f = renderer.render(ssrlab.scenes.mirror_test(), settings=small(width=160, height=90, method=method,
                                                                     sampling="mirror"))
    truth = f.reference("per_ray")
    assert truth.hit.any()
    assert ssrlab.reference.coverage(f, truth) >= 0.99
    assert np.median(ssrlab.reference.hit_position_error(f, truth)) < 0.1


@pytest.mark.parametrize("method", ["linear", "hiz"])
def test_per_ray_reference_exposes_what_one_layer_misses(renderer, method):
    scene, cam = floating_box()
    cov, visible = {}, {}
    for layers in (1, 2, 4):
        f = renderer.render(scene, cam, small(width=128, height=96, layers=layers, method=method, sampling="mirror"))
        truth = f.reference("per_ray")
        box = truth.hit & (truth.object == 1)  # rays that truly hit the box
        assert box.sum() > 100
        cov[layers] = ssrlab.reference.coverage(f, truth)
        found = ssrlab.reference.ssr_found(f, truth)
        visible[layers] = (found[box].mean(), (truth.in_gbuffer[box] >= 0).mean())
    assert cov[2] > cov[1] + 0.02 and cov[4] >= cov[2] - 1e-9, cov
    # With one layer the box's hidden faces are not in the G-buffer; with two they are.
    assert visible[1][1] < visible[2][1] - 0.05, visible


def test_shading_of_hits_matches_the_lit_gbuffer(renderer):
    """The reference shades a surface exactly as the lighting pass does (camera as viewer):
    where a true hit lies on a pixel's centre and that surface is in the G-buffer there, its
    radiance equals the pixel's lit colour, up to the G-buffer's storage: albedo in 8-bit sRGB
    (as the thesis's 4-byte colour), lit in RGBA16F; the reference keeps floats."""
    scene = ssrlab.scenes.spheres_and_boxes(seed=2)
    f = renderer.render(scene, settings=small(width=160, height=90, rays_per_pixel=16, layers=2))
    truth = f.reference("per_ray", viewer="camera", shadows="map")  # the lighting pass's view and shadows
    layer = truth.in_gbuffer
    px = truth.hit_pixel
    centred = np.all(np.abs(px - (np.floor(px) + 0.5)) < 0.05, axis=-1)
    m = truth.on_screen & (layer >= 0) & centred
    # Not on a silhouette (another object among the 8 neighbours in that layer): there the lit
    # colour changes by up to 0.4 per pixel, so 0.05 px off the centre is already 2 % of it.
    ids = np.pad(f.gbuffer.object_id, ((0, 0), (1, 1), (1, 1)), constant_values=-1)
    hgt, wid = f.gbuffer.object_id.shape[1:]
    edge = np.zeros(f.gbuffer.object_id.shape, bool)
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            edge |= ids[:, dy:dy + hgt, dx:dx + wid] != f.gbuffer.object_id
    ij_all = np.clip(np.floor(px).astype(int), 0, [wid - 1, hgt - 1])
    m &= ~edge[np.maximum(layer, 0), ij_all[..., 1], ij_all[..., 0]]
    assert m.sum() > 50
    ij = np.floor(px[m]).astype(int)
    lit = f.gbuffer.lit[layer[m], ij[:, 1], ij[:, 0]]
    err = np.abs(truth.radiance[m] - lit).max(axis=-1) / (np.abs(lit).max(axis=-1) + 0.1)
    # Most within 1 %; dark albedo channels, where an 8-bit sRGB step is a few per cent, within 4 %.
    assert (err < 0.01).mean() > 0.9 and err.max() < 0.04, (np.mean(err < 0.01), err.max())


def test_converged_reference_converges(renderer):
    scene = ssrlab.scenes.spheres_and_boxes(seed=1, floor_roughness=0.5)
    f = renderer.render(scene, settings=small(width=64, height=48))
    ref = {n: f.reference("converged", rays=n, seed=9).reflection.copy() for n in (8, 32, 128)}
    mask = ssrlab.reference.reflective_mask(f)
    e1 = np.abs(ref[8] - ref[128])[mask].mean()
    e2 = np.abs(ref[32] - ref[128])[mask].mean()
    assert e2 < 0.7 * e1, (e1, e2)
    for r in ref.values():
        assert_finite(r, "reference")


def test_reference_image_cache(renderer, tmp_path):
    scene = ssrlab.scenes.mirror_test()
    s = small(width=64, height=48)
    a = ssrlab.reference.reference_image(renderer, scene, settings=s, kind="converged", rays=1, folder=tmp_path)
    files = list(tmp_path.glob("*.npz"))
    assert len(files) == 1
    b = ssrlab.reference.reference_image(renderer, scene, settings=s, kind="converged", rays=1, folder=tmp_path)
    np.testing.assert_array_equal(a.color, b.color)
    # The tracer's own settings do not change the key; the scene and the image size do.
    ssrlab.reference.reference_image(renderer, scene, settings=s.replace(method="hiz", stride=4), kind="converged",
                                     rays=1, folder=tmp_path)
    assert len(list(tmp_path.glob("*.npz"))) == 1
    scene.set_material(0, ssrlab.Material(base_color=(1, 0, 0), metallic=1, roughness=0, reflectivity=0.5))
    c = ssrlab.reference.reference_image(renderer, scene, settings=s, kind="converged", rays=1, folder=tmp_path)
    assert len(list(tmp_path.glob("*.npz"))) == 2 and not np.array_equal(a.color, c.color)


def test_thesis_ground_truth(renderer, tmp_path):
    scene = ssrlab.scenes.box_stack()
    s = small(width=64, height=48)
    gt = ssrlab.reference.reference_image(renderer, scene, settings=s, kind="thesis", folder=tmp_path)
    direct = renderer.render(scene, settings=s.replace(rays_per_pixel=32, layers=16, stride=1.0, method="linear"))
    np.testing.assert_array_equal(gt.color, direct.color)


def test_reference_needs_the_frames_scene(renderer):
    scene = ssrlab.scenes.mirror_test()
    f = renderer.render(scene, settings=small())
    scene.set_material(0, ssrlab.Material(base_color=(1, 0, 0)))
    with pytest.raises(ValueError, match="scene"):
        f.reference("converged", rays=1)
    with pytest.raises(ValueError, match="kind"):
        renderer.render(scene, settings=small()).reference("exact")
