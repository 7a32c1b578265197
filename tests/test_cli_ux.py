"""The command line's user-facing forms: scoring against a reference, repeated timings,
settings, version, help, misspelled setting names."""

import json
import subprocess
import sys

import numpy as np
import pytest

import ssrlab


def run_cli(*args, cwd=None, env=None):
    return subprocess.run([sys.executable, "-m", "ssrlab", *args], capture_output=True, text=True, cwd=cwd,
                          env=env)


@pytest.fixture
def cache_env(tmp_path, monkeypatch):
    import os

    env = dict(os.environ, SSRLAB_CACHE=str(tmp_path / "cache"))
    monkeypatch.setenv("SSRLAB_CACHE", str(tmp_path / "cache"))
    return env


def test_render_reference_prints_metrics_and_writes_reference_and_error(tmp_path, cache_env, renderer):
    out = tmp_path / "out"
    args = ["render", "--scene", "mirror_test", "--width", "64", "--height", "48", "--set", "shadow_map_size=256",
            "--reference", "converged", "--rays", "4", "--out", str(out)]
    r = run_cli(*args, env=cache_env)
    assert r.returncode == 0, r.stderr
    assert "thesis error" in r.stdout and "RMSE" in r.stdout and "PSNR" in r.stdout
    assert (out / "reference.exr").is_file() and (out / "error.png").is_file()
    ref, channels = ssrlab.io.read_image(out / "reference.exr")
    assert ref.shape == (48, 64, 3)
    err, _ = ssrlab.io.read_image(out / "error.png")
    assert err.shape[:2] == (48, 64)
    record = json.loads((out / "timings.json").read_text())["reference"]
    # The printed and recorded figures are the metrics of the written images.
    color, _ = ssrlab.io.read_image(out / "color.exr")
    truth = ssrlab.reference.reference_image(renderer, ssrlab.scenes.mirror_test(),
                                             settings=ssrlab.Settings(width=64, height=48, shadow_map_size=256),
                                             rays=4)
    expected = ssrlab.metrics.image_metrics(color, ref, truth.reflective)
    assert record["thesis_error"] == pytest.approx(expected["thesis_error"], rel=1e-5)
    assert record["psnr"] == pytest.approx(expected["psnr"], rel=1e-5)
    assert f"{expected['psnr']:.2f}" in r.stdout
    assert np.allclose(truth.color, ref, atol=1e-6)
    # An error.png changed by the user is never replaced without --overwrite.
    (out / "error.png").write_bytes(b"mine")
    again = run_cli(*args, env=cache_env)
    assert again.returncode == 1 and "error.png" in again.stderr and "changed since ssrlab wrote it" in again.stderr
    assert (out / "error.png").read_bytes() == b"mine"
    assert run_cli(*args, "--overwrite", env=cache_env).returncode == 0


def test_render_thesis_reference_rejects_rays(tmp_path):
    r = run_cli("render", "--reference", "thesis", "--rays", "8", "--out", str(tmp_path / "x"))
    assert r.returncode != 0 and "--rays applies to --reference converged" in r.stderr


def test_render_repeats_reports_median_min_max(tmp_path):
    out = tmp_path / "out"
    r = run_cli("render", "--scene", "mirror_test", "--width", "48", "--height", "32", "--repeats", "3",
                "--out", str(out))
    assert r.returncode == 0, r.stderr
    assert "median (min - max) of 3 renders after 1 warm-up" in r.stdout
    record = json.loads((out / "timings.json").read_text())
    assert record["repeats"] == 3 and record["warmup"] == 1
    for name, median in record["timings_median_ms"].items():
        assert record["timings_min_ms"][name] <= median <= record["timings_max_ms"][name]
    assert "total" in record["timings_median_ms"]


def test_settings_version_and_help():
    r = run_cli("settings")
    # Against a fresh process's description: this one's lists the user passes earlier tests registered.
    fresh = subprocess.run([sys.executable, "-c", "import ssrlab; print(ssrlab.Settings.describe())"],
                           capture_output=True, text=True, timeout=120)
    assert fresh.returncode == 0 and "[constraints]" in fresh.stdout
    assert r.returncode == 0 and r.stdout.strip() == fresh.stdout.strip()
    r = run_cli("--version")
    assert r.returncode == 0 and r.stdout.strip() == f"ssrlab {ssrlab.__version__}"
    from importlib.metadata import version

    assert ssrlab.__version__ == version("ssrlab")


@pytest.mark.parametrize("command", ["render", "bench"])
def test_every_flag_has_help(command):
    import argparse

    from ssrlab import cli

    parsers = {}
    real = argparse.ArgumentParser.parse_args

    def capture(self, *a, **k):  # the top-level parser, before it runs anything
        parsers["top"] = self
        raise SystemExit(0)

    argparse.ArgumentParser.parse_args = capture
    try:
        with pytest.raises(SystemExit):
            cli.main([command])
    finally:
        argparse.ArgumentParser.parse_args = real
    top = parsers["top"]
    sub = next(a for a in top._actions if isinstance(a, argparse._SubParsersAction)).choices[command]
    for parser in (top, sub):
        for action in parser._actions:
            if isinstance(action, (argparse._HelpAction, argparse._SubParsersAction)):
                continue
            assert action.help, f"{command}: {action.option_strings or action.dest} has no help"


def test_misspelled_setting_suggests_the_nearest_field():
    r = run_cli("render", "--set", "metod=hiz", "--out", "/tmp/never")
    assert r.returncode != 0 and "did you mean 'method'" in r.stderr
    with pytest.raises(ValueError, match="did you mean 'method'"):
        ssrlab.Settings(metod="hiz")
    with pytest.raises(ValueError, match="did you mean 'layers'"):
        ssrlab.Settings().replace(layres=2)
    with pytest.raises(ValueError, match="did you mean 'rays_per_pixel'"):
        ssrlab.Settings.from_dict({"ray_per_pixel": 2})
    with pytest.raises(AttributeError, match="did you mean 'stride'"):
        ssrlab.Settings().strid = 2.0
    with pytest.raises(ValueError, match="unknown Settings field") as e:
        ssrlab.Settings(qqqqqq=1)
    assert "did you mean" not in str(e.value)
