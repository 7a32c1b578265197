"""Renderer.clear_path: clears by image stores (the GPU default) give the frames that GL's
clears give, bit for bit, in every pass that clears (peeling's colour layers, lighting, classify,
Hi-Z, pre-convolution, pre-integration, the list constructions' heads)."""

import numpy as np
import pytest

import ssrlab
from conftest import gpu_paths_skip, small

CASES = {
    "hiz_skip": dict(layers=3, method="hiz", skip=True),
    "linear_noskip": dict(layers=2, method="linear", skip=False),
    "hiz_cone_glossy": dict(layers=2, method="hiz", glossy="cone", skip=True),
    # The list constructions clear their lists' heads (passes/clear_buffer.comp), leaving the
    # storage bindings of the passes after them (the motion's previous transforms) as they were.
    "lists": dict(layers=3, method="hiz", deep_gbuffer="lists", motion_vectors=True),
    "visibility_lists": dict(layers=3, method="hiz", deep_gbuffer="visibility_lists", motion_vectors=True),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_compute_clears_give_the_same_frame(case):
    r = ssrlab.Renderer()
    scene = ssrlab.scenes.spheres_and_boxes(seed=2)
    s = small(width=48, height=32, **CASES[case])
    frames = {}
    for path in ("gl", "compute"):
        r.clear_path = path
        assert r.info["clear_path"] == path
        f = r.render(scene, settings=s)
        frames[path] = {"color": f.color, "lit": f.read("lit"), "normal": f.read("gbuffer.normal"),
                        "albedo": f.read("gbuffer.albedo"), "material": f.read("gbuffer.material"),
                        "rays.sample": f.read("rays.sample")}
        if s.motion_vectors:
            frames[path]["motion"] = f.gbuffer.motion
            assert np.all(f.gbuffer.motion == 0), f"{case} {path}: nothing moved"
    for name, a in frames["gl"].items():
        np.testing.assert_array_equal(a, frames["compute"][name], err_msg=f"{case}: {name}")
    assert np.any(frames["gl"]["albedo"][1] != 0) or CASES[case]["layers"] == 1  # a second layer was drawn


@gpu_paths_skip
def test_clear_path_is_validated():
    r = ssrlab.Renderer()
    assert r.info["clear_path"] == ("gl" if r.info["device"] == "cpu" else "compute")  # auto
    with pytest.raises(ValueError, match="clear_path"):
        r.clear_path = "fast"
