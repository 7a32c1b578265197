"""Glossy methods (seed 002, 4.4.2-4.4.5): the glossy setting, the pre-convolved colour
and pre-integrated visibility pyramids, the GGX cone angle, cone tracing and blurred mips."""

from __future__ import annotations

import re

import numpy as np
import pytest

import ssrlab
from ssrlab import glossy
from ssrlab.metrics import image_metrics

from conftest import REPO, assert_finite, small


def scene_with_roughness(name: str, roughness: float) -> ssrlab.Scene:
    if name == "mirror_test":
        scene = ssrlab.scenes.mirror_test()
        m = scene.material(0)
        m.roughness = roughness
        scene.set_material(0, m)
        return scene
    return ssrlab.scenes.load(name, floor_roughness=roughness)


def test_glossy_settings_are_validated():
    s = ssrlab.Settings()
    assert s.glossy == "stochastic" and s.to_native().glossy == "stochastic"
    with pytest.raises(ValueError, match="Settings.glossy"):
        ssrlab.Settings(glossy="cones")
    with pytest.raises(ValueError, match="Settings.cone_max_samples"):
        ssrlab.Settings(cone_max_samples=0)
    with pytest.raises(ValueError, match="Settings.cone_level_bias"):
        ssrlab.Settings(cone_level_bias=9.0)
    with pytest.raises(ValueError, match="Settings.cone_remainder"):
        ssrlab.Settings(cone_remainder="sky")
    native = ssrlab.Settings(glossy="blur_mips", cone_remainder="environment").to_native()
    assert native.glossy == "blur_mips" and native.cone_remainder == "environment"
    with pytest.raises(ValueError, match="Settings.glossy"):
        native.glossy = "nope"
    assert "glossy" in ssrlab.Settings.describe()


def test_the_chain_holds_the_glossy_passes_only_when_asked(renderer):
    scene = ssrlab.scenes.hall()
    passes = {g: renderer.render(scene, settings=small(method="hiz", glossy=g)).passes
              for g in ("stochastic", "cone", "blur_mips")}
    assert not {"preconvolve", "preintegrate", "cone_trace", "blur_mips"} & set(passes["stochastic"])
    assert "resolve" in passes["stochastic"]
    cone = passes["cone"]
    assert "resolve" not in cone and "blur_mips" not in cone
    assert cone.index("hiz_build") < cone.index("preintegrate") < cone.index("cone_trace")
    assert cone.index("preconvolve") < cone.index("cone_trace") < cone.index("composite")
    assert "preintegrate" not in passes["blur_mips"] and "blur_mips" in passes["blur_mips"]
    # The cone needs the Hi-Z whatever tracer follows its mirror ray.
    linear = renderer.render(scene, settings=small(method="linear", glossy="cone")).passes
    assert "hiz_build" in linear and "trace_linear" in linear and "cone_trace" in linear
    # One mirror ray per pixel, whatever rays_per_pixel says.
    f = renderer.render(scene, settings=small(method="hiz", glossy="cone", rays_per_pixel=4))
    assert f.read("rays.hit").shape[0] == 1


# What a technique overrides shows where the settings are read back: cone tracing and the blurred
# mips trace one mirror ray per pixel (seed 002 4.4, seed 004), so a frame or a sweep row that said
# 4 GGX rays would claim work that was not done.
@pytest.mark.parametrize("technique", ["cone", "blur_mips"])
def test_the_frame_and_the_sweep_row_say_what_the_technique_ran(renderer, technique, tmp_path):
    asked = small(method="hiz", glossy=technique, rays_per_pixel=4, sampling="vndf")
    f = renderer.render(ssrlab.scenes.load("box_stack"), settings=asked)
    assert (f.settings.rays_per_pixel, f.settings.sampling) == (1, "mirror")
    assert f.read("rays.hit").shape[0] == 1
    # One rule, the native one: Python's copy is what RenderSettings::as_run runs.
    native = asked._native_fields().as_run()
    assert (native.rays_per_pixel, native.sampling) == (f.settings.rays_per_pixel, f.settings.sampling)
    rows = ssrlab.bench.sweep({"rays_per_pixel": [1, 4]}, ["box_stack"], base=asked.replace(rays_per_pixel=1),
                              repeats=1, warmup=0, reference="thesis", progress=False, cache_folder=tmp_path)
    assert [(r["s_rays_per_pixel"], r["s_sampling"]) for r in rows] == [(1, "mirror"), (1, "mirror")]


# Odd sizes on purpose: 75 x 45 -> 37 x 22 -> 18 x 11 -> 9 x 5 -> 4 x 2 -> 2 x 1 -> 1 x 1.
@pytest.mark.parametrize("scene_name,layers", [("hall", 1), ("box_stack", 4)])
def test_preconvolution_keeps_the_covered_mean_at_every_level(renderer, scene_name, layers):
    f = renderer.render(ssrlab.scenes.load(scene_name), settings=small(width=75, height=45, method="hiz",
                                                                      glossy="cone", layers=layers))
    lit = f.gbuffer.lit
    cov = f.gbuffer.coverage
    level0 = f.read("lit_preconvolved", 0)
    np.testing.assert_allclose(level0[..., 3], cov, atol=0)
    np.testing.assert_allclose(level0[..., :3], lit * cov[..., None], rtol=1e-3, atol=1e-6)
    levels = int(np.floor(np.log2(max(75, 45)))) + 1
    checked = 0
    for layer in range(layers):
        covered = cov[layer] > 0.5
        if covered.sum() == 0:
            continue
        mean0 = lit[layer][covered].astype(np.float64).mean(axis=0)
        lo, hi = lit[layer][covered].min(axis=0), lit[layer][covered].max(axis=0)
        for level in range(levels):
            t = f.read("lit_preconvolved", level)[layer].astype(np.float64)
            assert t.shape[:2] == (max(45 >> level, 1), max(75 >> level, 1))
            mean = t[..., :3].sum(axis=(0, 1)) / t[..., 3].sum()
            np.testing.assert_allclose(mean, mean0, rtol=1e-4, atol=1e-7,
                                       err_msg=f"layer {layer} level {level}")
            # No bleeding: every texel's colour is a convex mix of covered level-0 colours.
            some = t[..., 3] > 1e-4
            colour = t[some][:, :3] / t[some][:, 3:]
            assert (colour >= lo - 1e-4).all() and (colour <= hi + 1e-4).all()
            checked += 1
    assert checked >= levels


def _children_mean(finer: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """Mean of each coarse cell's children, grouped as hiz_build groups them (odd sizes: the
    last cell takes the third row/column)."""
    h, w = size
    fh, fw = finer.shape
    out = np.zeros(size)
    for y in range(h):
        y1 = fh if y == h - 1 else min(2 * y + 2, fh)
        for x in range(w):
            x1 = fw if x == w - 1 else min(2 * x + 2, fw)
            out[y, x] = finer[2 * y:y1, 2 * x:x1].mean()
    return out


def test_preintegrated_visibility_never_grows_up_the_pyramid(renderer):
    f = renderer.render(ssrlab.scenes.spheres_and_boxes(seed=1), settings=small(
        width=75, height=45, method="hiz", glossy="cone", layers=2))
    v0 = f.read("visibility", 0)[..., 0]
    np.testing.assert_array_equal(v0, f.gbuffer.coverage)
    strictly_lower = 0
    finer = v0
    for level in range(1, 7):
        v = f.read("visibility", level)[..., 0]
        for layer in range(2):
            # Rows flipped back to GL order so the odd-size grouping matches the pyramid's.
            fine_gl, coarse_gl = finer[layer][::-1], v[layer][::-1]
            mean = _children_mean(fine_gl, coarse_gl.shape)
            assert (coarse_gl <= mean + 5e-4).all(), f"level {level} layer {layer}"  # R16F rounding
            assert (coarse_gl >= 0).all() and (coarse_gl <= 1).all()
            strictly_lower += int((coarse_gl < mean - 0.01).sum())
        finer = v
    assert strictly_lower > 0  # depth gaps (silhouettes) do lower it


@pytest.fixture(scope="module")
def lobe_renderer():
    return ssrlab.Renderer("auto")


def test_cone_angle_holds_the_stated_share_of_ggx_samples(lobe_renderer):
    """The cone around the mirror direction holds CONE_ENERGY of the VNDF sampler's directions,
    within 2 %, off the table's nodes too (fresh seeds)."""
    worst = 0.0
    for roughness in (0.05, 0.1, 0.2, 0.3, 0.45, 0.6, 0.8):
        for n_dot_v in (0.15, 0.4, 0.7, 0.95, 1.0):
            angles = glossy.lobe_angles(lobe_renderer, roughness, n_dot_v, count=1 << 14, seed=4242)
            share = float(np.mean(angles <= glossy.cone_angle(roughness, n_dot_v)))
            worst = max(worst, abs(share - glossy.CONE_ENERGY))
            assert abs(share - glossy.CONE_ENERGY) <= 0.02, (roughness, n_dot_v, share)
    assert worst > 0.0
    # A wrong mapping fails: the Phong-style angle of seed 002 (xi = 0.244) for a comparable power.
    power = 2.0 / 0.2 ** 4 - 2.0
    phong = np.arccos(0.244 ** (1.0 / (power + 1.0)))
    angles = glossy.lobe_angles(lobe_renderer, 0.2, 0.7, count=1 << 14, seed=4242)
    assert abs(np.mean(angles <= phong) - glossy.CONE_ENERGY) > 0.02


def test_the_shaders_read_the_same_cone_table():
    text = (REPO / "shaders/lib/cone_angle.glsl").read_text()
    body = text.split("CONE_THETA_OVER_ALPHA[CONE_ROUGHNESS_NODES * CONE_NV_NODES] =")[1].split(";")[0]
    numbers = np.array([float(x) for x in re.findall(r"-?\d+\.\d+", body)])
    np.testing.assert_allclose(numbers, glossy.CONE_TABLE.ravel(), atol=1e-5)
    nv = text.split("CONE_NV[CONE_NV_NODES] =")[1].split(";")[0]
    np.testing.assert_allclose([float(x) for x in re.findall(r"\d+\.\d+", nv)], glossy.NV_NODES, atol=1e-6)


@pytest.mark.parametrize("layers", [1, 4])
def test_cone_tracing_at_roughness_zero_is_mirror_tracing(renderer, layers):
    scene = ssrlab.scenes.mirror_test()
    base = dict(width=128, height=80, method="hiz", layers=layers)
    mirror = renderer.render(scene, settings=small(**base, sampling="mirror"))
    for g in ("cone", "blur_mips"):
        f = renderer.render(scene, settings=small(**base, glossy=g))
        per_pixel = np.abs(f.color.astype(np.float64) - mirror.color).sum(axis=-1)  # the thesis's error
        assert per_pixel.max() <= 1e-3, g
    assert mirror.rays.hit.mean() > 0.1  # the mirror does reflect the wall


@pytest.mark.parametrize("glossy_method", ["cone", "blur_mips"])
def test_glossy_outputs_are_finite_everywhere(renderer, glossy_method):
    for name in ssrlab.scenes.SCENES:
        for roughness in (0.0, 0.05, 0.2, 0.5, 1.0):
            scene = scene_with_roughness(name, roughness)
            for layers in (1, 4):
                f = renderer.render(scene, settings=small(width=64, height=40, method="hiz", layers=layers,
                                                          glossy=glossy_method))
                assert_finite(f.color, f"{name} roughness {roughness} layers {layers} color")
                assert_finite(f.reflection, f"{name} roughness {roughness} layers {layers} reflection")
                assert (f.reflection >= 0).all()


def test_cone_tracing_beats_one_stochastic_ray_on_a_glossy_floor(renderer):
    """hall, floor roughness 0.2: cone tracing's error against the converged reference is below
    one GGX ray per pixel's with the same (default) resolve, for both GGX samplers."""
    scene = ssrlab.scenes.hall(floor_roughness=0.2)
    base = dict(width=160, height=96, method="hiz")
    cone = renderer.render(scene, settings=small(**base, glossy="cone"))
    truth = cone.reference("converged", rays=64)
    e_cone = image_metrics(cone.color, truth.color, truth.reflective)["thesis_error_reflective"]
    for sampling in ("ggx", "vndf"):
        stoch = renderer.render(scene, settings=small(**base, glossy="stochastic", rays_per_pixel=1,
                                                      sampling=sampling))
        e_stoch = image_metrics(stoch.color, truth.color, truth.reflective)["thesis_error_reflective"]
        assert e_cone < e_stoch, (sampling, e_cone, e_stoch)


def test_cone_stretch_changes_only_glossy_grazing_reflections(renderer):
    """Settings.cone_stretch (seed 002, 4.6.8) reshapes the cone's footprints: it changes a rough
    floor's reflection, stays finite, and leaves a mirror alone."""
    scene = ssrlab.scenes.hall(floor_roughness=0.3)
    base = dict(width=96, height=64, method="hiz", glossy="cone")
    plain = renderer.render(scene, settings=small(**base)).reflection
    stretched = renderer.render(scene, settings=small(**base, cone_stretch=True)).reflection
    assert_finite(stretched, "stretched reflection")
    assert np.abs(stretched - plain).max() > 1e-3
    mirror = ssrlab.scenes.mirror_test()
    a = renderer.render(mirror, settings=small(**base)).reflection
    b = renderer.render(mirror, settings=small(**base, cone_stretch=True)).reflection
    np.testing.assert_array_equal(a, b)
