"""The converged reference traced by Embree on the CPU (tracer="embree") against the same
reference traced by the GLSL BVH (tracer="glsl"): the same rays from the same RNG streams, shaded
by the same GLSL, so they may differ only where the two intersection tests round differently (a
ray grazing a triangle edge, a hit distance a few ulps apart). docs/reference_tracers.md."""

from __future__ import annotations

import numpy as np
import pytest

import ssrlab
from conftest import model_path, small

# The stated bound, per image (final colour and reflection alike): PSNR against the GLSL tracer's
# image >= 60 dB, and at most 0.2% of the pixels more than 1e-3 apart (edge rays the two tests
# decide differently); everywhere else the pixels agree to 1e-3.
MIN_PSNR_DB = 60.0
MAX_DIFFERING_SHARE = 0.002
CLOSE = 1e-3


def psnr(a: np.ndarray, b: np.ndarray) -> float:
    peak = max(float(np.abs(b).max()), 1e-6)
    mse = float(np.mean((a - b) ** 2))
    return float("inf") if mse == 0 else 10 * np.log10(peak * peak / mse)


def agreement(renderer, scene, settings, **kw):
    frame = renderer.render(scene, settings=settings)
    glsl = frame.reference("converged", tracer="glsl", **kw)
    want = {"color": glsl.color.copy(), "reflection": glsl.reflection.copy()}
    emb = frame.reference("converged", tracer="embree", **kw)
    got = {"color": emb.color, "reflection": emb.reflection}
    assert emb.rays_traced and emb.rays_traced > 0
    assert glsl.rays_traced is None
    for key in want:
        a, b = got[key], want[key]
        assert np.isfinite(a).all()
        p = psnr(a, b)
        differing = float((np.abs(a - b).max(axis=-1) > CLOSE).mean())
        assert p >= MIN_PSNR_DB and differing <= MAX_DIFFERING_SHARE, (
            f"{scene.name} {key} {kw}: {p:.1f} dB, {differing:.4%} of pixels differ by more than {CLOSE}")
    return emb


@pytest.mark.parametrize("name", list(ssrlab.scenes.SCENES))
@pytest.mark.parametrize("sampling, rays", [("mirror", 1), ("vndf", 3)])
def test_embree_reference_equals_glsl_on_every_scene(renderer, name, sampling, rays):
    scene = ssrlab.scenes.load(name)
    agreement(renderer, scene, small(width=80, height=48, method="off"), rays=rays, sampling=sampling)


@pytest.mark.parametrize("rel", ["Suzanne/Suzanne.gltf", "2CylinderEngine/2CylinderEngine.glb"])
@pytest.mark.parametrize("roughness", [0.0, 0.35])
def test_embree_reference_equals_glsl_on_the_models(renderer, rel, roughness):
    scene = ssrlab.scenes.load(str(model_path(rel)))
    lo, hi = (np.asarray(b, dtype=float) for b in scene.bounds)
    size = float(np.max(hi - lo)) * 3
    scene.add_plane(((lo[0] + hi[0]) / 2, lo[1], (lo[2] + hi[2]) / 2), (size, size), name="floor",
                    material=ssrlab.Material(base_color=(0.6, 0.6, 0.6), roughness=roughness, reflectivity=0.8))
    agreement(renderer, scene, small(width=64, height=48, method="off"), rays=3)


def test_tracer_is_checked_and_auto_follows_the_device(renderer):
    scene = ssrlab.scenes.load("mirror_test")
    frame = renderer.render(scene, settings=small(width=32, height=24, method="off"))
    with pytest.raises(ValueError, match="tracer"):
        frame.reference("converged", rays=1, tracer="optix")
    ref = frame.reference("converged", rays=1)
    # "auto": the C++ tracer on the CPU device (tests/test_reference_cpu.py), the GLSL on a GPU
    assert ("reference.cpu" in ref.timings) == (renderer.info["device"] == "cpu")
    assert {"reference.shade", "reference.intersect"} <= set(frame.reference("converged", rays=1,
                                                                             tracer="embree").timings)


def test_progress_is_called_per_round_and_can_stop(renderer):
    scene = ssrlab.scenes.load("spheres_and_boxes")
    frame = renderer.render(scene, settings=small(width=32, height=24, method="off"))
    for tracer in ("glsl", "embree"):
        seen = []
        frame.reference("converged", rays=20, tracer=tracer, progress=lambda d, t: seen.append((d, t)))
        # (once per dispatch, which may hold several rays: 8 for the wavefront)
        assert seen[-1] == (20, 20) and seen == sorted(set(seen)), (tracer, seen)
        if tracer == "embree":
            assert seen == [(8, 20), (16, 20), (20, 20)]
        with pytest.raises(RuntimeError, match="stopped"):
            frame.reference("converged", rays=3, tracer=tracer, progress=lambda d, t: d < 2)
