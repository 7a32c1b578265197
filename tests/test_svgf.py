"""The SVGF denoiser of the reflection (seed 003; Schied et al. 2017)."""

import numpy as np
import pytest

import ssrlab
from ssrlab import metrics, scenes

from conftest import small

SVGF_PASSES = ("svgf_temporal", "svgf_variance", "svgf_atrous")


@pytest.mark.parametrize("field, value, match", [
    ("denoise", "bilateral", "denoise"), ("svgf_iterations", 9, "svgf_iterations"),
    ("svgf_max_history", 0, "svgf_max_history"), ("svgf_sigma_luminance", 0.0, "svgf_sigma_luminance"),
    ("svgf_sigma_depth", -1.0, "svgf_sigma_depth"), ("svgf_sigma_normal", 2000.0, "svgf_sigma_normal"),
])
def test_denoiser_settings_are_validated(field, value, match):
    with pytest.raises(ValueError, match=match):
        ssrlab.Settings(**{field: value})


def test_svgf_and_temporal_reflections_exclude_each_other():
    with pytest.raises(ValueError, match="temporal_reflections"):
        ssrlab.Settings(denoise="svgf", temporal_reflections=True)


@pytest.fixture(scope="module")
def glossy():
    return scenes.spheres_and_boxes(seed=1, count=8, floor_roughness=0.2)


def test_one_ray_with_svgf_over_8_frames_beats_four_rays_without(renderer, glossy):
    """1-ray glossy reflections (roughness 0.2, static camera, 8 frames) with
    the denoiser score a lower error against the converged reference than 4-ray reflections
    without it. One ray per pixel as seed 003 traces them: no neighbour-ray reuse in the resolve
    (reuse_radius=0) for either."""
    s = small(width=128, height=80, rays_per_pixel=1, reuse_radius=0)
    frames = list(renderer.render_sequence(glossy, [glossy.camera] * 8, s.replace(denoise="svgf")))
    assert all(p in frames[-1].timings for p in SVGF_PASSES)
    four = renderer.render(glossy, settings=s.replace(rays_per_pixel=4))
    assert not any(p in four.timings for p in SVGF_PASSES)
    ref = frames[-1].reference("converged", rays=64, viewer="camera", shadows="map")
    mask = ref.reflective & (frames[-1].gbuffer.roughness[0] > 0.1)
    assert mask.sum() > 2000
    e_svgf = metrics.rmse(frames[-1].reflection, ref.reflection, mask)
    e_first = metrics.rmse(frames[0].reflection, ref.reflection, mask)
    e_raw = metrics.rmse(frames[-1].read("reflection")[0, :, :, :3], ref.reflection, mask)
    e_four = metrics.rmse(four.reflection, ref.reflection, mask)
    # Measured at 128x80: 0.0555 (svgf, frame 8) against 0.0682 (4 rays) and 0.105 (1 ray).
    assert e_svgf < 0.9 * e_four, (e_svgf, e_four)
    assert e_svgf < e_first < e_raw, (e_svgf, e_first, e_raw)
    assert np.isfinite(frames[-1].reflection).all()
    # Deterministic: the same sequence again gives the same image.
    again = list(renderer.render_sequence(glossy, [glossy.camera] * 8, s.replace(denoise="svgf")))
    np.testing.assert_array_equal(again[-1].reflection, frames[-1].reflection)


def test_without_wavelets_svgf_accumulates_as_the_temporal_pass_does(renderer, glossy):
    """svgf_iterations=0 leaves the accumulation alone: on the glossy pixels it is the plain
    mean of the same frames that temporal_reflections computes (the shared reprojection)."""
    s = small(rays_per_pixel=1, temporal_max_history=8, svgf_max_history=8)
    cams = [glossy.camera] * 4
    den = list(renderer.render_sequence(glossy, cams, s.replace(denoise="svgf", svgf_iterations=0)))[-1]
    acc = list(renderer.render_sequence(glossy, cams, s.replace(temporal_reflections=True)))[-1]
    glossy_px = den.gbuffer.coverage[0] & (den.gbuffer.reflectivity[0] > 0) & (den.gbuffer.roughness[0] > 0.1)
    assert glossy_px.sum() > 500
    np.testing.assert_allclose(den.reflection[glossy_px], acc.reflection[glossy_px], atol=1e-5)
    assert np.abs(den.read("svgf.moments")[0, :, :, 2][glossy_px] - 4).max() == 0  # four frames of history


def test_single_render_filters_glossy_pixels_and_leaves_mirrors(renderer):
    """A render() outside a sequence has no history: the spatial variance and the wavelets only.
    Glossy pixels change; mirror pixels (roughness 0: one ray is exact) keep what was traced."""
    scene = scenes.spheres_and_boxes(seed=1, count=8, floor_roughness=0.2)
    f = renderer.render(scene, settings=small(denoise="svgf"))
    raw = f.read("reflection")[0, :, :, :3]
    glossy_px = f.gbuffer.coverage[0] & (f.gbuffer.reflectivity[0] > 0) & (f.gbuffer.roughness[0] > 0.1)
    assert np.isfinite(f.reflection).all()
    assert np.abs(f.reflection - raw)[glossy_px].mean() > 1e-3
    # And the change lowers the noise: the distance to the estimator's own expectation (the mean
    # of many independent one-ray renders, so that SSR's bias cancels) falls on the glossy pixels.
    expectation = np.mean([renderer.render(scene, settings=small(seed=k)).reflection for k in range(1, 13)], axis=0)
    noise = lambda img: float(np.sqrt(np.mean((img[glossy_px] - expectation[glossy_px]) ** 2)))  # noqa: E731
    assert noise(f.reflection) < 0.9 * noise(raw), (noise(f.reflection), noise(raw))
    mirror = renderer.render(scenes.spheres_and_boxes(seed=1, count=8, floor_roughness=0.0),
                             settings=small(denoise="svgf"))
    np.testing.assert_array_equal(mirror.reflection, mirror.read("reflection")[0, :, :, :3])


def test_hybrid_sweep_file_plans_every_configuration():
    from pathlib import Path

    from ssrlab import bench, hybrid
    cfg = bench.load_sweep(Path(__file__).resolve().parents[1] / "benchmarks/sweeps/hybrid.toml")
    plan = bench.plan_sweep(cfg["grid"], cfg["scenes"], None, cfg["base"])  # every configuration is valid
    assert len(plan) == 3 * 12 and cfg["frames"] == 8  # 2 methods x 3 fallbacks x 2 denoisers, 3 scenes
    assert {c["settings"]["fallback"] for c in plan} == {"environment", "probes", "bvh"}
    assert {c["settings"]["denoise"] for c in plan} == {"none", "svgf"}
    # The notebook's list has probes exactly when the Settings validation accepts them.
    assert ("SSR + probes" in hybrid.configurations()) == hybrid.probes_available()
    assert set(hybrid.configurations()) >= {"SSR only", "SSR + BVH fallback", "pure BVH"}
