"""Golden frames: fixed configurations whose colour and reflection must stay bit-identical on the CPU
device through a restructuring of the renderer (every deep G-buffer construction, tracer, glossy
method, fallback, denoiser, downscale, skip and reversed-Z, over two scenes, at small sizes).

The digests live in tests/data/golden_frames.json. A change that alters an image on purpose writes
them again with SSRLAB_UPDATE_GOLDEN=1 and says why in its commit; a restructuring never does."""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import numpy as np
import pytest

import ssrlab

from conftest import GPU_PATHS

GOLDEN = Path(__file__).parent / "data" / "golden_frames.json"
SIZE = dict(width=64, height=36)
CONFIGS = {
    "peel": dict(layers=3, deep_gbuffer="peel"),
    "lists": dict(layers=3, deep_gbuffer="lists"),
    "visibility": dict(layers=3, deep_gbuffer="visibility"),
    "visibility_lists": dict(layers=3, deep_gbuffer="visibility_lists"),
    "linear": dict(method="linear", rays_per_pixel=2, sampling="vndf"),
    "hiz": dict(method="hiz", rays_per_pixel=2, sampling="vndf"),
    "bvh": dict(method="bvh"),
    "cone": dict(method="hiz", glossy="cone"),
    "blur_mips": dict(method="hiz", glossy="blur_mips"),
    "fallback_none": dict(fallback="none"),
    "fallback_bvh": dict(method="hiz", fallback="bvh"),
    "fallback_probes": dict(fallback="probes"),
    "svgf": dict(denoise="svgf"),
    "downscale": dict(downscale=2, rays_per_pixel=2),
    "skip_off": dict(skip=False),
    "skip_on": dict(skip=True),
    "reversed_z": dict(depth_mode="reversed_z", method="hiz"),
    "taa_temporal": dict(taa="clamped", temporal_reflections=True),
}
SCENES = ("hall", "box_stack")

pytestmark = pytest.mark.skipif(GPU_PATHS, reason="the golden frames are the CPU device's default paths")


def digest(a: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(a, np.float32).tobytes()).hexdigest()


@pytest.fixture(scope="module")
def renderer():
    r = ssrlab.Renderer("cpu")
    yield r


@pytest.fixture(scope="module")
def golden():
    return json.loads(GOLDEN.read_text()) if GOLDEN.exists() else {}


@pytest.fixture(scope="module")
def scenes():
    return {name: ssrlab.scenes.load(name) for name in SCENES}


# The chain's order comes from the passes' declarations, ties between passes that do not depend on
# each other broken by name (render/pass_registry.h); broken the other way, every image must stay
# the same: no order a pass relies on is left undeclared.
TIES = ("names", "reverse")


@pytest.mark.parametrize("ties", TIES)
@pytest.mark.parametrize("scene_name", SCENES)
@pytest.mark.parametrize("config", list(CONFIGS))
def test_golden_frame(renderer, scenes, golden, scene_name, config, ties, monkeypatch):
    if ties == "reverse":
        if os.environ.get("SSRLAB_UPDATE_GOLDEN") == "1":
            pytest.skip("the golden frames are written with the chain's own order")
        monkeypatch.setenv("SSRLAB_CHAIN_TIES", "reverse")
    else:
        monkeypatch.delenv("SSRLAB_CHAIN_TIES", raising=False)
    scene = scenes[scene_name]
    if config == "fallback_probes":
        scene = scene.copy()
        lo, hi = (np.asarray(b, float) for b in scene.bounds)
        scene.probes = [tuple((lo + hi) / 2)]
    frame = renderer.render(scene, settings=ssrlab.Settings(**SIZE, **CONFIGS[config]))
    got = {"color": digest(frame.color), "reflection": digest(frame.reflection), "passes": frame.passes,
           "mean": float(np.mean(frame.color))}
    key = f"{scene_name}/{config}"
    if os.environ.get("SSRLAB_UPDATE_GOLDEN") == "1":
        data = json.loads(GOLDEN.read_text()) if GOLDEN.exists() else {}
        data[key] = got
        GOLDEN.write_text(json.dumps(dict(sorted(data.items())), indent=1) + "\n")
        return
    assert key in golden, f"no golden frame {key}: write them with SSRLAB_UPDATE_GOLDEN=1"
    want = golden[key]
    assert sorted(got["passes"]) == sorted(want["passes"]), f"{key}: the chain runs other passes"
    assert got["color"] == want["color"], f"{key}: colour differs (mean {got['mean']!r}, golden {want['mean']!r})"
    assert got["reflection"] == want["reflection"], f"{key}: reflection differs"
