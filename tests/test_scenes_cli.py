"""Procedural scenes and the command line."""

import json
import subprocess
import sys

import numpy as np
import pytest

import ssrlab
from conftest import small


@pytest.mark.parametrize("name", list(ssrlab.scenes.SCENES))
def test_procedural_scene_has_camera_lights_and_renders(renderer, name):
    scene = ssrlab.scenes.load(name)
    assert scene.camera is not None and scene.lights and scene.object_count > 0
    f = renderer.render(scene, settings=small())
    cov = f.gbuffer.coverage[0]
    assert 0.2 < cov.mean() <= 1.0, "the default camera must look at the scene"
    assert f.color.std() > 0.01, "a flat image is a bug"


def test_seed_changes_the_scene_and_is_deterministic():
    a, b, c = (ssrlab.scenes.spheres_and_boxes(seed=s) for s in (1, 1, 2))
    ta = [a.object_transform(i).tolist() for i in range(a.object_count)]
    assert ta == [b.object_transform(i).tolist() for i in range(b.object_count)]
    assert ta != [c.object_transform(i).tolist() for i in range(c.object_count)]


def test_box_stack_needs_many_layers(renderer):
    g = renderer.render(ssrlab.scenes.box_stack(), settings=small(width=160, height=90, layers=8)).gbuffer
    share = g.coverage.reshape(8, -1).mean(axis=1)
    assert share[3] > 0.05, f"layer coverage {share}"


def test_unknown_scene():
    with pytest.raises(ValueError, match="unknown scene"):
        ssrlab.scenes.load("cathedral")


def run_cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "ssrlab", *args], capture_output=True, text=True, cwd=cwd)


def test_cli_render_writes_outputs_and_runs_twice(tmp_path):
    out = tmp_path / "out"
    args = ["render", "--scene", "box_stack", "--width", "80", "--height", "48", "--layers", "2", "--out", str(out)]
    first = run_cli(*args)
    assert first.returncode == 0, first.stderr
    names = sorted(p.name for p in out.iterdir())
    assert names == sorted([".ssrlab-manifest.json", "color.png", "color.exr", "gbuffer_layer0.exr",
                            "gbuffer_layer1.exr", "timings.json"])
    timings = json.loads((out / "timings.json").read_text())
    assert timings["timings_ms"]["deep_gbuffer"] > 0 and timings["settings"]["layers"] == 2
    pixels, channels = ssrlab.io.read_image(out / "gbuffer_layer1.exr")
    # OpenEXR stores channels sorted by name; every channel must be there.
    assert pixels.shape == (48, 80, len(ssrlab.io.GBUFFER_CHANNELS))
    assert sorted(channels) == sorted(ssrlab.io.GBUFFER_CHANNELS)
    png, _ = ssrlab.io.read_image(out / "color.png")
    assert png.shape == (48, 80, 3) and png.std() > 0.01
    second = run_cli(*args)
    assert second.returncode == 0, second.stderr


def test_cli_never_overwrites_a_users_file(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "color.png").write_text("my own picture")
    args = ["render", "--scene", "mirror_test", "--width", "32", "--height", "32", "--out", str(out)]
    r = run_cli(*args)
    assert r.returncode == 1 and "was not written by ssrlab" in r.stderr
    assert (out / "color.png").read_text() == "my own picture"
    assert not (out / "timings.json").exists()
    r = run_cli(*args, "--overwrite")
    assert r.returncode == 0, r.stderr


def test_cli_rejects_bad_settings():
    r = run_cli("render", "--set", "layers=99", "--out", "/tmp/never")
    assert r.returncode != 0 and "Settings.layers" in r.stderr


def test_cli_info():
    r = run_cli("info")
    assert r.returncode == 0 and "renderer" in r.stdout
