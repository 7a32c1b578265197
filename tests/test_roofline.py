"""Issue 13: the roofline's device-peak kernels and the benchmark script (small sizes; no timing is
asserted, only that every figure is a finite positive number), and the resolve's fast paths
leave images as they were."""

import importlib.util
import json
import math

import numpy as np
import pytest

import ssrlab
from conftest import REPO, small


@pytest.mark.parametrize("kernel", ["coherent", "dependent", "store", "bandwidth", "copy"])
def test_microbenchmark_kernels_time_every_repeat(renderer, kernel):
    ms = renderer.microbenchmark(kernel, 64, 48, 1 if kernel == "copy" else 4, repeats=3)
    assert len(ms) == 3
    assert all(math.isfinite(t) and t > 0.0 for t in ms), ms


@pytest.mark.parametrize("args, match", [
    (("fetch", 64, 64, 4), "kernel 'fetch' unknown"),
    (("coherent", 0, 64, 4), "width and height"),
    (("store", 64, 64, 17), "iterations must be in \\[1, 16\\]"),
    (("coherent", 64, 64, 0), "iterations"),
])
def test_microbenchmark_rejects_bad_arguments(renderer, args, match):
    with pytest.raises(ValueError, match=match):
        renderer.microbenchmark(*args, repeats=1)


def test_roofline_script_prints_finite_positive_figures(tmp_path, capsys):
    spec = importlib.util.spec_from_file_location("roofline", REPO / "benchmarks" / "roofline.py")
    roofline = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(roofline)
    out = tmp_path / "roofline.json"
    assert roofline.main(["--quick", "--device", "cpu", "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "| copy |" in text and "resolve / trace_hiz" in text
    result = json.loads(out.read_text())
    for p in result["peaks"].values():
        assert p["ms"] > 0 and math.isfinite(p["rate"]) and p["rate"] > 0
    rows = [r for cfg in result["configs"].values() for r in cfg["passes"].values()]
    assert any("share" in r for r in rows)
    for r in rows:
        assert math.isfinite(r["ms"]) and r["ms"] >= 0
        if "share" in r:
            assert r["fetches"] > 0 and r["rate"] > 0 and math.isfinite(r["share"])
    assert all(math.isfinite(v) and v > 0 for v in result["ratios"].values())
