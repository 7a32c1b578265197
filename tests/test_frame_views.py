"""Frame's views (GBuffer, RayResults, Reprojection, Frame.view) are made from the channels the passes
declare with their textures (ResourceDesc::channels): one meaning per channel whichever pass wrote
it, decoded as declared, and nothing decoded or patched by hand in Python."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import ssrlab

from conftest import small

CONSTRUCTIONS = ("peel", "lists", "visibility", "visibility_lists")


@pytest.fixture(scope="module")
def hall():
    return ssrlab.scenes.load("hall")


def declared(frame, view):
    return [(c["texture"], c["name"], c["first"], c["count"], c["decode"]) for c in frame.channels if c["view"] == view]


def test_every_construction_declares_the_same_gbuffer_channels(renderer, hall):
    seen = {}
    for construction in CONSTRUCTIONS:
        f = renderer.render(hall, settings=small(width=48, height=32, layers=2, deep_gbuffer=construction,
                                                 motion_vectors=True))
        seen[construction] = sorted(declared(f, "gbuffer"))
        names = {n for _, n, *_ in seen[construction]}
        assert {"depth", "window_depth", "normal", "albedo", "roughness", "metallic", "reflectivity", "coverage",
                "object_id", "lit", "motion"} <= names, (construction, names)
    assert all(v == seen["peel"] for v in seen.values()), seen


# Each decoding, written out from the raw texels, against what the view gives.
def by_hand(raw, decode, height):
    if decode == "value":
        return raw[..., 0] if raw.shape[-1] == 1 else raw
    if decode == "flag":
        return raw[..., 0] > 0.5
    if decode == "integer":
        return np.rint(raw[..., 0]).astype(np.int32)
    if decode == "byte_id_minus_one":
        return (np.rint(raw[..., 0] * 255) + 256 * np.rint(raw[..., 1] * 255)).astype(np.int32) - 1
    if decode == "window_point":
        return np.stack([raw[..., 0], height - raw[..., 1]], -1)
    if decode == "window_vector":
        return np.stack([raw[..., 0], -raw[..., 1]], -1)
    raise AssertionError(decode)


@pytest.mark.parametrize("view", ["gbuffer", "rays", "reprojection"])
def test_each_channel_is_its_texture_decoded_as_declared(renderer, hall, view):
    s = small(width=48, height=32, layers=2, temporal_reflections=True, motion_vectors=True)
    frame = renderer.render(hall, settings=s)
    if view == "reprojection" and "reprojection" not in frame.texture_names:
        pytest.skip("this chain has no reprojection")
    v = frame.view(view)
    assert v.channels, view
    decodes = set()
    for c in v.channels:
        raw = frame.read(c["texture"])[..., c["first"]:c["first"] + c["count"]]
        want = by_hand(raw, c["decode"], s.height)
        if not c["layered"]:
            want = want[0]
        got = getattr(v, c["name"])
        assert got.shape == want.shape and np.array_equal(got, want), c
        assert not got.flags.writeable
        decodes.add(c["decode"])
    assert decodes, view
    assert sorted(dir(v)) == sorted(set(dir(v)) | {c["name"] for c in v.channels})


def test_the_frames_decodings_cover_every_kind(renderer, hall):
    s = small(width=48, height=32, layers=2, temporal_reflections=True, motion_vectors=True)
    frame = renderer.render(hall, settings=s)
    assert {c["decode"] for c in frame.channels} == {"value", "flag", "integer", "byte_id_minus_one", "window_point",
                                                     "window_vector"}


def test_a_channel_the_frame_lacks_says_what_brings_it(renderer, hall):
    f = renderer.render(hall, settings=small(width=32, height=24))
    with pytest.raises(KeyError, match="motion_vectors") as e:
        f.gbuffer.motion
    assert isinstance(e.value, AttributeError) and "it has:" in str(e.value)
    assert not hasattr(f.gbuffer, "motion")
    with pytest.raises(ValueError, match="no view 'nothing'.*gbuffer"):
        f.view("nothing")


def test_skipped_pixels_read_as_no_ray_from_the_declaration(renderer, hall):
    # With skip the ray textures are written only where a ray was traced; their declarations say so
    # (defined where rays.sample's traced flag is set), and reading gives 0 elsewhere.
    f = renderer.render(hall, settings=small(width=48, height=32, skip=True))
    assert "classify" in f.passes
    traced = f.rays.traced_ray
    for name in ("rays.hit", "rays.direction"):
        raw = f.read(name)
        assert not raw[~traced].any(), name
    assert (~traced).any() and traced.any()


def test_python_decodes_no_texture_by_hand():
    # Texture names and decoding constants live in the passes' declarations, not in the views.
    src = (Path(ssrlab.__file__).parent / "frame_views.py").read_text()
    assert not re.findall(r"read\(\s*\"(?:gbuffer|rays|lit|linear_depth)", src)
    assert "* 255" not in src.split("def _decode")[0]
