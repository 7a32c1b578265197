"""The roofline's device-peak kernels and the benchmark scripts around it, run as scripts (small
sizes; no timing is asserted, only that every figure is a finite positive number), and the
resolve's fast paths leave images as they were."""

import json
import math
import re
import subprocess
import sys

import numpy as np
import pytest

import ssrlab
from conftest import REPO, benchmark_script, image_load_refusal, small


@pytest.mark.parametrize("kernel", ["coherent", "dependent", "dependent_image", "store", "bandwidth", "copy",
                                    "copy_image"])
def test_microbenchmark_kernels_time_every_repeat(renderer, kernel):
    ms = renderer.microbenchmark(kernel, 64, 48, 1 if kernel.startswith("copy") else 4, repeats=3)
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


def run_benchmark(name: str, *args: str) -> str:
    """A benchmark script's standard output, run as the script it is (never imported by path), on
    the device at hand (the scripts' default, --device auto)."""
    r = subprocess.run([sys.executable, str(benchmark_script(name)), *args], capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    return r.stdout


def test_roofline_script_prints_finite_positive_figures(tmp_path):
    out = tmp_path / "roofline.json"
    text = run_benchmark("roofline", "--quick", "--json", str(out))
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


def test_ab_pass_same_shaders_give_the_same_hits_and_lane_use_in_range():
    shaders = str(REPO / "shaders")
    text = run_benchmark("ab_pass", shaders, shaders, "--width", "96", "--height", "64", "--scenes", "hall",
                         "--repeats", "2", "--lane-use")
    assert "largest hit difference 0.00e+00 px" in text  # one shader tree, deterministic: same hits
    uses = [float(x) for x in re.findall(r"(?:i\+32|consecutive entries) ([0-9.]+)", text)]
    assert len(uses) == 2 and all(0.0 < u <= 1.0 for u in uses), text


def test_lane_use_is_one_for_equal_walks_and_the_share_of_the_longest_otherwise():
    from ssrlab.lab.lanes import lane_use

    steps = np.full((64, 64), 5.0)
    assert lane_use(steps) == {"entries i, i+32": 1.0, "16 consecutive entries": 1.0}
    steps[0, 0] = 10.0  # one long walk: its vector pays 16 x 10 for 15 x 5 + 10 used
    use = lane_use(steps)
    total = steps.sum()
    assert use["16 consecutive entries"] == pytest.approx(total / (total + 15 * 5))


# -- the resolve's fast paths -------------------------------------------------------------------

def _general_resolve_shaders(tmp_path):
    """A copy of the shader tree whose resolve takes the general path everywhere: no group vote,
    the shared tile even where only a pixel's own rays count or where resolve_fetch's textures
    serve it (imageLoad), one ray per chunk (two barriers per ray, the plain
    path)."""
    import shutil

    root = tmp_path / "shaders"
    shutil.copytree(ssrlab.renderer.shader_dir(), root)
    path = root / "passes" / "resolve.comp"
    text = path.read_text()
    patches = [("#ifndef OWN_RAYS_ONLY\n#define OWN_RAYS_ONLY 0\n#endif", "#undef OWN_RAYS_ONLY\n#define OWN_RAYS_ONLY 0"),
               ("#ifndef RESOLVE_SHARED_TILE\n#define RESOLVE_SHARED_TILE 1\n#endif",
                "#undef RESOLVE_SHARED_TILE\n#define RESOLVE_SHARED_TILE 1"),
               ("if (s_any_receiver == 0u) {", "if (false) {"),
               ("int chunk = max(1, TILE_CAPACITY / entries);", "int chunk = 1;")]
    for old, new in patches:
        assert text.count(old) == 1, f"resolve.comp no longer has {old!r}: update this test"
        text = text.replace(old, new)
    path.write_text(text)
    return root


@pytest.mark.parametrize("scene_name, kw", [
    ("hall", dict(layers=1, method="hiz", sampling="mirror")),                      # own rays only
    ("hall", dict(layers=2, rays_per_pixel=4, stride=4.0, downscale=2, max_steps=250)),  # thesis: one chunk
    ("spheres_and_boxes", dict(layers=2, rays_per_pixel=3, reuse_radius=2)),        # chunks of 1 at s=1
    ("spheres_and_boxes", dict(layers=1, rays_per_pixel=2, reuse_weighting="thesis", skip=False)),
])
def test_resolve_fast_paths_leave_the_image_unchanged(renderer, tmp_path, scene_name, kw):
    from ssrlab import metrics

    general = ssrlab.Renderer(shader_dir=_general_resolve_shaders(tmp_path))
    scene = getattr(ssrlab.scenes, scene_name)()
    s = small(width=128, height=72, **kw)
    # The general path over the whole image (skip off): with skip the resolve runs over the
    # classify pass's list, whose form (pixels or tiles) follows the fast path.
    general_settings = small(width=128, height=72, **{**kw, "skip": False})
    fast, slow = renderer.render(scene, settings=s), general.render(scene, settings=general_settings)
    assert np.asarray(fast.reflection).any(), "nothing reflects: the comparison would prove nothing"
    # Only the sums' order may differ (neighbours outer, rays inner): float rounding.
    err = np.abs(np.asarray(fast.reflection) - np.asarray(slow.reflection)).sum(axis=-1)
    assert err.max() <= 1e-3, err.max()
    assert metrics.thesis_error(fast.color, slow.color) <= 1e-4


def test_device_agreement_of_one_device_with_itself_is_exact(tmp_path):
    for name in ("a.npz", "b.npz"):
        run_benchmark("device_agreement", "save", str(tmp_path / name), "--width", "48", "--height", "32",
                      "--scenes", "mirror_test")
    text = run_benchmark("device_agreement", "compare", str(tmp_path / "a.npz"), str(tmp_path / "b.npz"))
    rows = [line for line in text.splitlines() if line.startswith("| mirror_test.")]
    assert len(rows) == 6 and all("| 0.00000 | 0.00000 | 0.000 | 0.00 % |" in r for r in rows)


# What the scripts measure, named here so that a case the script drops fails the test.
BREAKDOWN_CASES = ("hiz_mirror", "skip_on", "reuse0", "start_level0", "max_steps64", "layers4", "thesis")
READBACK_TEXTURES = {"color": "direct", "lit": "direct", "gbuffer.albedo": "copy pass", "gbuffer.material": "copy pass"}
TRACE_PARTS = ("entries", "+ ray", "+ set-up", "+ walk", "+ hit", "full pass", "full, 1 store")


def test_frame_breakdown_prints_every_case_with_its_sub_passes():
    out = run_benchmark("frame_breakdown", "--width", "64", "--height", "48", "--repeats", "1", "--scenes",
                        "mirror_test")
    for case in BREAKDOWN_CASES:
        assert f"mirror_test {case} (skip=" in out
    assert "classify.clear" in out and "depth_peel.layer0" in out and "depth fetches per ray" in out


def test_readback_benchmark_times_both_paths_and_both_encodings_of_the_display_bytes():
    out = run_benchmark("readback", "--sizes", "48x32", "--repeats", "2")
    rows = [line for line in out.splitlines() if line.startswith("| 48x32 |")]
    reads = [r for r in rows if not r.startswith("| 48x32 | display bytes (ms) |")]
    encodings = [r for r in rows if r.startswith("| 48x32 | display bytes (ms) |")]
    assert {(r.split(" | ")[1], r.split(" | ")[2]) for r in reads} == set(READBACK_TEXTURES.items())
    assert len(encodings) == 1 and "| device / numpy |" in out
    assert "| staged / download |" in out and all(r.rstrip().endswith(("faster |", "slower |", "overlap) |"))
                                                   for r in rows)


def test_trace_parts_builds_every_part_of_the_pass():
    out = run_benchmark("trace_parts", "--width", "48", "--height", "32", "--repeats", "1", "--scenes", "hall")
    assert "| scene | " + " | ".join(TRACE_PARTS) + " |" in out
    rows = [line for line in out.splitlines() if line.startswith("| hall |")]
    assert len(rows) == 1 and rows[0].count(" ms") == 0 and rows[0].count("(") == len(TRACE_PARTS)


def test_input_fetch_benchmark_compares_both_fetches_and_refuses_a_verdict_on_two_frames():
    out = run_benchmark("input_fetch", "--width", "48", "--height", "32", "--repeats", "2", "--scenes", "hall")
    if image_load_refusal():  # the benchmark says so and compares nothing
        assert "imageLoad cannot run on this device, nothing to compare" in out and "| hall |" not in out
        return
    rows = [line for line in out.splitlines() if line.startswith("| hall |")]
    assert {r.split(" | ")[1] for r in rows} == {"hiz_mirror", "thesis"}
    assert any(" | total | " in r for r in rows)
    assert all(r.rstrip().endswith("too few frames to judge (--repeats < 5) |") for r in rows)
