"""Resolve (seed 000, 2.4), downscaled tracing (2.6), fades and fallback (seed 002, 4.6.1),
composite (2.4.2)."""

import numpy as np
import pytest

import ssrlab
from ssrlab.analytic import specular_albedo_lookup
from conftest import small


def test_missed_rays_take_the_environment(renderer):
    s = ssrlab.Scene()
    s.add_plane((0, 0, 0), 50, material=ssrlab.Material(base_color=(1, 1, 1), metallic=1, roughness=0,
                                                         reflectivity=1))
    s.environment = ssrlab.Environment.constant((0.3, 0.5, 0.7), intensity=2.0)
    cam = ssrlab.Camera(position=(0, 1, 3), target=(0, 0, 0))
    f = renderer.render(s, cam, small(sampling="mirror"))
    traced = f.rays.traced
    assert traced.any() and not f.rays.hit.any()
    np.testing.assert_allclose(f.reflection[traced], np.broadcast_to([0.6, 1.0, 1.4], (traced.sum(), 3)),
                               rtol=1e-3)


def test_sky_environment_is_the_background(renderer):
    s = ssrlab.Scene()
    s.environment = ssrlab.Environment.sky(zenith=(0, 0, 1), horizon=(1, 0, 0), ground=(0, 1, 0))
    up = renderer.render(s, ssrlab.Camera(position=(0, 0, 0), target=(0, 1, 0), up=(0, 0, -1), fov_y=10),
                         small()).color
    down = renderer.render(s, ssrlab.Camera(position=(0, 0, 0), target=(0, -1, 0), up=(0, 0, 1), fov_y=10),
                           small()).color
    assert up[..., 2].min() > 0.9 and down[..., 1].min() > 0.9


def test_environment_map(renderer, tmp_path):
    # An equirectangular map: red in the upper half (toward +y), blue in the lower.
    env = np.zeros((32, 64, 3), np.float32)
    env[:16] = (2.0, 0.0, 0.0)
    env[16:] = (0.0, 0.0, 3.0)
    ssrlab.io.write_image(tmp_path / "env.exr", env, ["R", "G", "B"])
    s = ssrlab.Scene()
    s.environment = ssrlab.Environment.map(str(tmp_path / "env.exr"))
    up = renderer.render(s, ssrlab.Camera(position=(0, 0, 0), target=(0, 1, 0), up=(0, 0, -1), fov_y=20),
                         small()).color
    np.testing.assert_allclose(up.mean(axis=(0, 1)), [2.0, 0.0, 0.0], atol=1e-3)
    with pytest.raises(FileNotFoundError):
        ssrlab.Environment.map(str(tmp_path / "missing.exr"))


def test_border_fade(renderer):
    scene = ssrlab.scenes.mirror_test()
    f = renderer.render(scene, settings=small(width=160, height=90, sampling="mirror", fade_border=0.2))
    rays = f.rays
    uv = rays.hit_uv[0][rays.hit[0]]
    fade = rays.fade[0][rays.hit[0]]
    edge = np.minimum.reduce([uv[:, 0] * 160, (1 - uv[:, 0]) * 160, uv[:, 1] * 90, (1 - uv[:, 1]) * 90])
    near = edge < 0.2 * 90
    assert near.any() and (~near).any()
    np.testing.assert_allclose(fade[~near], 1.0)
    np.testing.assert_allclose(fade[near], np.clip(edge[near] / 18.0, 0, 1), atol=1e-3)
    off = renderer.render(scene, settings=small(width=160, height=90, sampling="mirror", fade_border=0.0))
    np.testing.assert_array_equal(off.rays.fade[0][off.rays.hit[0]], 1.0)


def test_rays_toward_the_camera_fade(renderer):
    from test_tracing import floating_box
    scene, cam = floating_box()
    # A mirror behind the camera-facing box would send rays back; here use a tilted view:
    # every floor ray goes away from the camera, so no ray fades by direction.
    f = renderer.render(scene, cam, small(sampling="mirror", layers=2, fade_border=0.0))
    np.testing.assert_array_equal(f.rays.fade[f.rays.hit], 1.0)
    # Make the camera fade start below every ray's cosine: all hits fade completely.
    g = renderer.render(scene, cam, small(sampling="mirror", layers=2, fade_border=0.0,
                                          fade_camera_start=-1.0, fade_camera_end=-0.99))
    assert g.rays.hit.any()
    np.testing.assert_array_equal(g.rays.fade[g.rays.hit], 0.0)


def view_positions(frame, pixels_xy, depth):
    """View-space points at positive depth `depth` seen through pixel positions (x, y from the top)."""
    P, s = frame.projection_matrix, frame.settings
    ndc = np.stack([pixels_xy[..., 0] / s.width * 2 - 1, 1 - pixels_xy[..., 1] / s.height * 2], -1)
    return np.stack([ndc[..., 0] * depth / P[0, 0], ndc[..., 1] * depth / P[1, 1], -depth], -1)


def test_distance_fade(renderer):
    scene = ssrlab.scenes.mirror_test()
    f = renderer.render(scene, settings=small(sampling="mirror", fade_border=0.0, fade_distance_start=1.0,
                                              fade_distance_end=3.0))
    rays, g = f.rays, f.gbuffer
    rows, cols = np.nonzero(rays.hit[0])
    origin = view_positions(f, np.stack([cols + 0.5, rows + 0.5], -1), g.depth[0][rows, cols])
    hit_px = rays.hit_pixel[0][rows, cols]
    hit_depth = g.depth[0][np.floor(hit_px[:, 1]).astype(int), np.floor(hit_px[:, 0]).astype(int)]
    dist = np.linalg.norm(view_positions(f, hit_px, hit_depth) - origin, axis=-1)
    x = np.clip((dist - 1.0) / 2.0, 0, 1)
    expected = 1 - x * x * (3 - 2 * x)  # 1 - smoothstep(1, 3, distance)
    assert (expected < 0.5).any() and (expected > 0.5).any()
    np.testing.assert_allclose(rays.fade[0][rows, cols], expected, atol=0.02)


@pytest.mark.parametrize("mode", ["linear", "pbr"])
def test_composite_formula(renderer, mode):
    scene = ssrlab.scenes.spheres_and_boxes(seed=2)
    f = renderer.render(scene, settings=small(composite=mode, layers=2))
    g = f.gbuffer
    r = g.reflectivity[0][..., None]
    c_d, c_r = g.lit[0], f.reflection
    refl = (r[..., 0] > 0) & g.coverage[0]
    if mode == "linear":
        expected = r * c_r + (1 - r) * c_d
    else:
        # The GGX directional albedo E = F0 A + B at the view angle (split-sum table), F0 from
        # metallic/base colour.
        V = f.view_matrix
        P = f.projection_matrix
        h, w = f.settings.height, f.settings.width
        j, i = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
        ndc = np.stack([j / w * 2 - 1, 1 - i / h * 2], -1)
        z = g.depth[0]
        pos = np.stack([ndc[..., 0] * z / P[0, 0], ndc[..., 1] * z / P[1, 1], -z], -1)
        nv = np.clip(np.sum(g.normal[0] * -pos / np.linalg.norm(pos, axis=-1, keepdims=True), -1), 0, 1)
        f0 = 0.04 * (1 - g.metallic[0][..., None]) + g.albedo[0] * g.metallic[0][..., None]
        ab = specular_albedo_lookup(renderer.specular_albedo_table(), nv, g.roughness[0])
        expected = c_d + r * (f0 * ab[..., :1] + ab[..., 1:]) * c_r
    np.testing.assert_allclose(f.color[refl], expected[refl], rtol=2e-3, atol=2e-3)
    np.testing.assert_allclose(f.color[~refl & g.coverage[0]], c_d[~refl & g.coverage[0]], atol=1e-3)


def test_reuse_reduces_noise(renderer):
    scene = ssrlab.scenes.spheres_and_boxes(seed=4, floor_roughness=0.5)
    base = dict(width=128, height=72, rays_per_pixel=2, edge_aware=False)
    ref = renderer.render(scene, settings=small(width=128, height=72, rays_per_pixel=32, reuse_radius=2)).reflection
    errors = {}
    for radius in (0, 1, 2):
        for weighting in ("thesis", "brdf"):
            f = renderer.render(scene, settings=small(reuse_radius=radius, reuse_weighting=weighting, **base))
            mask = f.rays.traced & (f.gbuffer.roughness[0] > 0.4)
            errors[radius, weighting] = np.abs(f.reflection - ref)[mask].mean()
    for w in ("thesis", "brdf"):
        assert errors[1, w] < errors[0, w] and errors[2, w] < errors[0, w], errors



@pytest.mark.parametrize("kw", [
    dict(layers=2, rays_per_pixel=4, stride=4.0, downscale=2, max_steps=250),  # the thesis's configuration
    dict(rays_per_pixel=2, sampling="vndf"),                                  # full resolution, radius 1
])
def test_reuse_weights_equal_the_local_frame_formulation(renderer, tmp_path, kw):
    """The resolve weighs a neighbour's ray by brdf_cosine_over_pdf, the GGX terms
    rearranged over the cosines in view space, toward hit points precomputed per tile entry. The
    same sums with the plain formulation (local frame, half vector, ggx_D and two ggx_G1, the
    direction rebuilt from origin, direction and distance per pixel) give the same image."""
    import shutil

    from ssrlab import metrics

    root = tmp_path / "shaders"
    shutil.copytree(ssrlab.renderer.shader_dir(), root)
    path = root / "passes" / "resolve.comp"
    text = path.read_text()
    old = "float wb = brdf_cosine_over_pdf(g.normal, v, l, alpha, receiver, pdf);"
    assert text.count(old) == 1, "resolve.comp no longer weighs rays this way: update this test"
    path.write_text(text.replace(old, "mat3 local = transpose(frame_from_normal(g.normal)); "
                                      "float wb = brdf_cosine(local * v, local * l, alpha) / pdf;"))
    plain = ssrlab.Renderer(shader_dir=root)
    scene = ssrlab.scenes.spheres_and_boxes(seed=2, floor_roughness=0.2)
    s = small(width=128, height=72, **kw)
    fast, slow = renderer.render(scene, settings=s), plain.render(scene, settings=s)
    assert np.asarray(fast.reflection).any(), "nothing reflects: the comparison would prove nothing"
    # Float rounding only; the sharpest lobes (D at small alpha) amplify it the most.
    err = np.abs(np.asarray(fast.reflection) - np.asarray(slow.reflection)).sum(axis=-1)
    assert err.max() <= 1e-2, err.max()
    assert metrics.thesis_error(fast.color, slow.color) <= 1e-4

def test_downscaled_rays(renderer):
    scene = ssrlab.scenes.spheres_and_boxes(seed=1)
    for d in (1, 2, 4):
        f = renderer.render(scene, settings=small(width=100, height=60, downscale=d))
        assert f.rays.hit.shape == (1, -(-60 // d), -(-100 // d))
        assert f.reflection.shape == (60, 100, 3)


def silhouette_error(renderer, edge_aware):
    """Reflection error, against full-resolution tracing, on pixels next to a depth edge."""
    scene = ssrlab.scenes.box_stack(floor_roughness=0.0)
    kw = dict(width=160, height=96, sampling="mirror", edge_aware=edge_aware)
    full = renderer.render(scene, settings=small(**kw))
    half = renderer.render(scene, settings=small(downscale=2, **kw))
    z = full.gbuffer.depth[0]
    edge = np.zeros_like(z, bool)
    edge[1:-1, 1:-1] = np.maximum.reduce([np.abs(z[1:-1, 1:-1] - z[:-2, 1:-1]), np.abs(z[1:-1, 1:-1] - z[2:, 1:-1]),
                                          np.abs(z[1:-1, 1:-1] - z[1:-1, :-2]),
                                          np.abs(z[1:-1, 1:-1] - z[1:-1, 2:])]) > 0.1 * z[1:-1, 1:-1]
    mask = edge & full.rays.traced & (full.gbuffer.reflectivity[0] > 0)
    assert mask.sum() > 20
    return np.abs(half.reflection - full.reflection)[mask].mean()


def test_edge_aware_upsampling_keeps_reflections_inside_silhouettes(renderer):
    assert silhouette_error(renderer, True) < 0.8 * silhouette_error(renderer, False)


def test_roughness_cutoff_skips_rough_pixels(renderer):
    scene = ssrlab.scenes.spheres_and_boxes(seed=1, floor_roughness=0.6)
    f = renderer.render(scene, settings=small(roughness_cutoff=0.5))
    g = f.gbuffer
    rough = g.roughness[0] > 0.5
    assert not f.rays.traced[rough].any()
    assert f.rays.traced[~rough & (g.reflectivity[0] > 0)].all()
    # Rough reflective pixels reflect the environment instead (a sky: never black).
    fallback = rough & (g.reflectivity[0] > 0) & g.coverage[0]
    assert fallback.any() and f.reflection[fallback].min() > 0.05


def test_frames_without_reflective_surfaces_trace_nothing(renderer):
    scene = ssrlab.scenes.spheres_and_boxes()
    f = renderer.render(scene, settings=small(method="off"))
    assert f.passes == ["depth_peel", "shadow_map", "lighting", "composite"]
    matte = ssrlab.Scene()
    matte.add_sphere((0, 0, 0), 1)
    g = renderer.render(matte, ssrlab.Camera(), small(method="hiz"))
    assert "trace_hiz" not in g.passes and "hiz_build" not in g.passes
    with pytest.raises(ValueError, match="traced no rays"):
        g.rays
    np.testing.assert_array_equal(g.reflection, 0)
    h = renderer.render(scene, settings=small(method="hiz", skip=True))
    fetch = ["resolve_fetch"] if renderer.info["input_fetch"] == "imageLoad" else []
    assert h.passes == ["depth_peel", "hiz_build", "shadow_map", "lighting", "classify", "trace_hiz",
                        "specular_occlusion", *fetch, "resolve", "composite"]
    # The shadow map is f's, kept by the renderer (the matte scene in between casts none): not drawn again.
    assert h.stats["shadow_maps_reused"] == 1 and h.timings["shadow_map"] == 0
    assert all(h.timings[p] > 0 for p in h.passes if p != "shadow_map")


@pytest.mark.parametrize("field, value", [
    ("method", "cone"), ("rays_per_pixel", 0), ("rays_per_pixel", 33), ("sampling", "beckmann"), ("stride", 0.5),
    ("stride", -2), ("max_steps", 0), ("thickness", -0.1), ("thickness_mode", "auto"), ("downscale", 3),
    ("reuse_radius", 3), ("reuse_weighting", "mean"), ("fade_border", 0.7), ("hiz_start_level", -1),
    ("hiz_crossing_offset", 0.0), ("composite", "add"), ("refine_steps", 17), ("jitter", 2.0), ("seed", -1),
    ("roughness_cutoff", 1.5), ("noise", "white"),
])
def test_invalid_reflection_settings_name_the_field(field, value):
    with pytest.raises(ValueError, match=f"Settings.{field}"):
        ssrlab.Settings(**{field: value})


def test_settings_describe_every_field():
    text = ssrlab.Settings.describe()
    import dataclasses
    for f in dataclasses.fields(ssrlab.Settings):
        assert f"  {f.name} = " in text
