"""Golden frames: fixed configurations whose colour and reflection must stay bit-identical on the CPU
device through a restructuring of the renderer (every deep G-buffer construction, tracer, glossy
method, fallback, denoiser, downscale, skip and reversed-Z, over two scenes, at small sizes).

Bit-identical holds on one machine: llvmpipe compiles its rasteriser for the host CPU, and CPUs of
two vendors round its approximate reciprocals differently, so a rasterised G-buffer's last bits
(and every image shaded from it) differ between them while the compute paths agree. The digests in
tests/data/golden_frames.json are therefore kept per machine (CPU vendor and model, and llvmpipe's
name); on a machine that has none, each frame must equal some machine's digests or else lie within
THUMB_TOLERANCE of the stored 16x9 thumbnails, and the test says which held. A change that alters an
image on purpose writes them again with SSRLAB_UPDATE_GOLDEN=1 (this machine's digests and the
thumbnails) and says why in its commit; a restructuring never does."""

from __future__ import annotations

import hashlib
import json
import os
import re
import warnings
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


# Largest difference of a 4x4-pixel mean of colour or reflection from the stored thumbnail where this
# machine has no digests of its own: the two vendors' rasterisers put hall's frames 0.25 % apart.
THUMB_TOLERANCE = 0.01


def digest(a: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(a, np.float32).tobytes()).hexdigest()


def thumbnail(a: np.ndarray) -> np.ndarray:
    """(9, 16, 3) means of 4x4 pixels of a 64x36 image."""
    return np.asarray(a, np.float64).reshape(9, 4, 16, 4, 3).mean(axis=(1, 3))


def machine() -> str:
    """The CPU (vendor and model) and the llvmpipe build that the digests hold for."""
    cpu = {}
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            k, _, v = line.partition(":")
            if k.strip() in ("vendor_id", "model name") and k.strip() not in cpu:
                cpu[k.strip()] = v.strip()
    except OSError:
        pass
    import platform
    return f"{cpu.get('vendor_id', platform.machine())} {cpu.get('model name', platform.processor())}"


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
    here = f"{machine()}; {renderer.info['renderer']}"
    got = {"color": digest(frame.color), "reflection": digest(frame.reflection)}
    key = f"{scene_name}/{config}"
    if os.environ.get("SSRLAB_UPDATE_GOLDEN") == "1":
        data = json.loads(GOLDEN.read_text()) if GOLDEN.exists() else {}
        data.setdefault("frames", {})[key] = {
            "passes": frame.passes, "mean": float(np.mean(frame.color)),
            "thumb_color": np.round(thumbnail(frame.color), 6).tolist(),
            "thumb_reflection": np.round(thumbnail(frame.reflection), 6).tolist()}
        data.setdefault("machines", {}).setdefault(here, {})[key] = got
        data["machines"][here] = dict(sorted(data["machines"][here].items()))
        data["frames"] = dict(sorted(data["frames"].items()))
        # Innermost lists (a thumbnail's pixels) on one line each.
        text = re.sub(r"\[\s+([-0-9.e,\s]+?)\s+\]", lambda m: "[" + re.sub(r"\s+", " ", m.group(1)) + "]",
                      json.dumps(data, indent=1))
        GOLDEN.write_text(text + "\n")
        return
    assert key in golden.get("frames", {}), f"no golden frame {key}: write them with SSRLAB_UPDATE_GOLDEN=1"
    want = golden["frames"][key]
    assert sorted(frame.passes) == sorted(want["passes"]), f"{key}: the chain runs other passes"
    machines = golden.get("machines", {})
    if here in machines:
        mine = machines[here]
        assert key in mine, f"no golden frame {key} for this machine ({here}): write them with SSRLAB_UPDATE_GOLDEN=1"
        assert got["color"] == mine[key]["color"], f"{key}: colour differs (mean {np.mean(frame.color)!r}, golden {want['mean']!r})"
        assert got["reflection"] == mine[key]["reflection"], f"{key}: reflection differs"
        return
    if any(m.get(key) == got for m in machines.values()):
        return  # bit-identical to another machine's frame
    for name, image in (("colour", frame.color), ("reflection", frame.reflection)):
        off = float(np.abs(thumbnail(image) - np.asarray(want[f"thumb_{name}" if name != "colour" else "thumb_color"])).max())
        assert off <= THUMB_TOLERANCE, (f"{key}: {name} differs from the thumbnails by {off:.4f} (> {THUMB_TOLERANCE}); "
                                        f"this machine ({here}) has no digests of its own")
    warnings.warn(f"{key}: this machine ({here}) has no golden digests; the frame matched the thumbnails "
                  f"within {THUMB_TOLERANCE}, not bit for bit", stacklevel=1)
