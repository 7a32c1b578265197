"""Benchmarks as records (ssrlab.lab.records, ssrlab.lab.protocol): the format written and read
back, tables rendered from records, `ssrlab bench compare` on a folder against itself and against
a copy whose timing samples are doubled, and the standard evaluation with a user entry."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from conftest import REPO, benchmark_script
from ssrlab.lab import protocol, records


def fake_run(folder, seed=0, scale=1.0):
    """Records of a made-up benchmark: times with a few per cent of noise, 5 samples each, and
    single-valued errors (deterministic)."""
    rng = np.random.default_rng(seed)
    rec = records.Recorder("fake", folder, None, command="python benchmarks/fake.py")
    for scene in ("hall", "box_stack"):
        for layers in (1, 4, 8):
            base = 2.0 * layers + (1.0 if scene == "hall" else 3.0)
            for metric in ("total", "trace"):
                rec.add({"scene": scene, "layers": layers}, metric, "ms",
                        scale * base * (1 + 0.03 * rng.standard_normal(5)))
            rec.add({"scene": scene, "layers": layers}, "thesis_error", "", [0.01 * layers])
    return rec


def run_cli(*args, timeout=300, cwd=REPO):
    env = {**os.environ, "SSRLAB_PERCEPTUAL": "0"}
    return subprocess.run([sys.executable, "-m", "ssrlab", *args], capture_output=True, text=True, cwd=cwd,
                          env=env, timeout=timeout)


def test_a_record_holds_every_field_and_reads_back(tmp_path):
    rec = fake_run(tmp_path)
    back = records.read_records(tmp_path)
    assert back == rec.records and (tmp_path / "fake.jsonl").is_file()
    for r in back:
        assert set(records.FIELDS) <= set(r)
        assert r["commit"] and r["date"] and r["command"] == "python benchmarks/fake.py"
    assert len(back[0]["samples"]) == 5 and back[0]["unit"] == "ms"
    # A second run appends; the latest record of a figure is the one compared.
    fake_run(tmp_path, seed=1)
    assert len(records.read_records(tmp_path)) == 2 * len(back)
    assert len(records.latest(records.read_records(tmp_path))) == len(back)


def test_quick_records_say_so(tmp_path):
    rec = records.Recorder("fake", tmp_path, None, quick=True)
    assert rec.add({"scene": "hall"}, "total", "ms", [1, 2, 3])["params"]["quick"] is True


def test_a_table_is_rendered_from_records():
    rec = fake_run(None)
    text = records.table(rec.find("total"), ["scene", "layers"], "metric")
    lines = text.splitlines()
    assert lines[0] == "| scene | layers | total (ms) |" and len(lines) == 2 + 6
    assert all(line.count("[") == 1 for line in lines[2:])
    assert records.cell([3.0]) == "3.00" and records.cell([1, 2, 3, 4, 5]) == "3.00 [2.00-4.00]"


def test_set_is_parsed_in_one_place():
    assert protocol.parse_set(["method=hiz", "layers=4", "skip=true"]) == {"method": "hiz", "layers": 4,
                                                                           "skip": True}
    with pytest.raises(ValueError, match="FIELD=VALUE"):
        protocol.parse_set(["method"])


def test_goal_verdicts_come_from_the_rounds():
    assert protocol.goal_verdict([1.1, 1.2, 1.15, 1.12], "<=", 2.0) == "met"
    assert protocol.goal_verdict([2.1, 2.2, 2.15, 2.3], "<=", 2.0) == "not met"
    assert protocol.goal_verdict([1.8, 2.2, 1.9, 2.1], "<=", 2.0).startswith("undecided at this noise")
    assert protocol.goal_verdict([1.0, 1.0], "<=", 2.0).startswith("undecided")


def test_verdict_rule():
    old = {"samples": [10.0, 10.2, 9.9, 10.1, 10.0], "unit": "ms"}
    assert records.figure_verdict(old, old)[0] == "same"
    assert records.figure_verdict(old, {**old, "samples": [2 * v for v in old["samples"]]})[0] == "slower"
    assert records.figure_verdict(old, {**old, "samples": [v / 2 for v in old["samples"]]})[0] == "faster"
    noisy = {"samples": [5.0, 15.0, 9.0, 12.0, 7.0], "unit": "ms"}
    assert records.figure_verdict(old, noisy)[0] == "undecided"
    two = {"samples": [10.0, 11.0], "unit": "ms"}
    assert records.figure_verdict(two, two)[0] == "same"  # the very same samples
    assert records.figure_verdict(two, {**two, "samples": [10.0, 11.5]})[0] == "undecided"  # too few to tell
    psnr = {"samples": [40.0], "unit": "dB", "better": "higher"}
    assert records.figure_verdict(psnr, {**psnr, "samples": [44.0]})[0] == "better"


def test_compare_of_a_folder_with_itself_finds_nothing_faster_or_slower(tmp_path):
    fake_run(tmp_path / "a")
    r = run_cli("bench", "compare", str(tmp_path / "a"), str(tmp_path / "a"), "--json", str(tmp_path / "c.json"))
    assert r.returncode == 0, r.stderr
    rows = json.loads((tmp_path / "c.json").read_text())
    assert len(rows) == 18 and all(row["verdict"] in ("same", "undecided") for row in rows)
    assert "faster" not in r.stdout and "slower" not in r.stdout and "| verdict |" in r.stdout


def test_compare_against_doubled_timings_says_slower(tmp_path):
    fake_run(tmp_path / "a")
    (tmp_path / "b").mkdir()
    for line in (tmp_path / "a" / "fake.jsonl").read_text().splitlines():
        rec = json.loads(line)
        if records.is_timing(rec):
            rec["samples"] = [2 * v for v in rec["samples"]]
        with open(tmp_path / "b" / "fake.jsonl", "a") as f:
            f.write(json.dumps(rec) + "\n")
    r = run_cli("bench", "compare", str(tmp_path / "a"), str(tmp_path / "b"), "--json", str(tmp_path / "c.json"))
    assert r.returncode == 0, r.stderr
    rows = json.loads((tmp_path / "c.json").read_text())
    timing = [row for row in rows if row["timing"]]
    assert len(timing) == 12
    assert sum(row["verdict"] == "slower" for row in timing) >= 0.8 * len(timing)
    assert all(row["verdict"] == "same" for row in rows if not row["timing"])


def test_compare_reads_a_commits_records(tmp_path):
    """git:<commit>:<folder> reads committed records through git show (a folder of this repository
    with records in its history; skipped where the checkout has none committed yet)."""
    listed = subprocess.run(["git", "-C", str(REPO), "ls-tree", "-r", "--name-only", "HEAD", "benchmarks/results"],
                            capture_output=True, text=True)
    folders = sorted({p.rsplit("/", 1)[0] for p in listed.stdout.splitlines() if p.endswith(".jsonl")})
    if not folders:
        pytest.skip("no committed records at HEAD")
    rows = records.compare(records.read_records(f"git:HEAD:{folders[0]}"),
                           records.read_records(f"git:HEAD:{folders[0]}"))
    assert rows and not any(r["verdict"] in ("faster", "slower") for r in rows)


def test_a_figure_over_commits_is_read_from_the_committed_records_and_drawn(tmp_path):
    """ssrlab bench history: a figure at each commit that changed it, from the commits' own records
    (the llvmpipe deep G-buffer records were committed at two commits at least), and its plot."""
    folder = "benchmarks/results/llvmpipe-llvm-15-0-6-256-bits"
    if len(records.commits_of(folder)) < 2:
        pytest.skip("this checkout's history holds fewer than two commits of the llvmpipe records")
    rows = records.history(folder, "deep_gbuffer", "x_floor", {"scene": "hall", "layers": 8, "method": "peel"})
    assert len({r["commit"] for r in rows}) >= 2
    assert all(r["n"] >= 3 and r["p25"] <= r["median"] <= r["p75"] for r in rows)
    # A commit appears only where the figure's record changed.
    assert len({(r["date"], r["recorded_at"]) for r in rows}) == len(rows)
    png = tmp_path / "history.png"
    run = subprocess.run([sys.executable, "-m", "ssrlab", "bench", "history", folder, "deep_gbuffer", "x_floor",
                          "--param", "scene=hall", "--param", "layers=8", "--plot", str(png)],
                         capture_output=True, text=True, timeout=120, cwd=REPO)
    assert run.returncode == 0, run.stderr
    assert "| commit |" in run.stdout and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    bad = subprocess.run([sys.executable, "-m", "ssrlab", "bench", "history", folder, "deep_gbuffer", "no_such"],
                         capture_output=True, text=True, timeout=120, cwd=REPO)
    assert bad.returncode == 1 and "no record of deep_gbuffer / no_such" in bad.stderr


def test_a_converted_benchmark_writes_records_and_prints_their_table(tmp_path):
    r = subprocess.run([sys.executable, str(REPO / "benchmarks" / "timing" / "frame_breakdown.py"), "--width", "48", "--height",
                        "32", "--repeats", "3", "--scenes", "mirror_test", "--records", str(tmp_path)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    recs = records.read_records(tmp_path)
    total = [x for x in recs if x["metric"] == "total"]
    assert len(total) >= 7 and all(len(x["samples"]) == 3 for x in total)
    assert all(x["benchmark"] == "frame_breakdown" and x["params"]["scene"] == "mirror_test" for x in recs)
    assert "| scene | case |" in r.stdout


def test_the_standard_evaluation_gives_an_entry_its_row_beside_every_builtin_technique(tmp_path):
    from ssrlab.lab.standard import TECHNIQUES

    r = run_cli("--device", "cpu", "bench", "--suite", "standard", "--quick", "--entry",
                "examples/bilateral_filter/technique.py:bilateral_filter", "--out", str(tmp_path / "std"))
    assert r.returncode == 0, r.stderr[-3000:]
    board = (tmp_path / "std" / "leaderboard.md").read_text()
    recs = records.read_records(tmp_path / "std")
    scenes = {x["params"]["scene"] for x in recs}
    assert len(scenes) >= 2 and all(x["params"]["quick"] for x in recs)
    for technique in [*TECHNIQUES, "entry: bilateral_filter"]:
        for scene in scenes:
            mine = records.select(recs, technique=technique, scene=scene)
            assert {x["metric"] for x in mine} >= {"thesis_error", "psnr", "frame", "reflection"}, (technique, scene)
            assert all(len(x["samples"]) >= 3 for x in mine if x["unit"] == "ms")
        row = [line for line in board.splitlines() if line.startswith(f"| {technique} |")]
        assert len(row) == 1 + len(scenes), technique  # the overall table and each scene's
        assert all("-" not in line.split(" | ")[1] for line in row)  # an error in every row


def _registry() -> dict:
    """run_all's registry, as the script prints it (a test imports no script by path)."""
    r = subprocess.run([sys.executable, str(REPO / "benchmarks" / "run_all.py"), "--registry"], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 0, r.stderr[-2000:]
    return json.loads(r.stdout)


RUN_ALL = _registry()

def test_every_registered_benchmark_has_a_smoke_run():
    """Every benchmark run_all runs writes records (none is exempt), and its script is in a genre folder."""
    assert set(RUN_ALL["smoke"]) == set(RUN_ALL["benchmarks"])
    assert all(RUN_ALL["scripts"][name].count("/") == 2 for name in RUN_ALL["benchmarks"])


@pytest.mark.parametrize("name", sorted(RUN_ALL["smoke"]))
def test_a_registered_benchmark_writes_valid_records(tmp_path, name):
    """Each benchmark of run_all's registry, at its smoke size, appends records to
    <folder>/<name>.jsonl with every field filled, marked quick, and prints a table rendered from
    them (Markdown, not laid out by hand)."""
    r = subprocess.run([sys.executable, str(benchmark_script(name)), *RUN_ALL["smoke"][name], "--device", "auto",
                        "--records", str(tmp_path), "--records-quick"], capture_output=True, text=True, timeout=300,
                       cwd=REPO, env={**os.environ, "SSRLAB_PERCEPTUAL": "0"})
    assert r.returncode == 0, r.stderr[-3000:]
    assert [p.name for p in tmp_path.glob("*.jsonl")] == [f"{name}.jsonl"]
    recs = records.read_records(tmp_path)
    assert recs
    for x in recs:
        assert set(records.FIELDS) <= set(x), x
        assert x["benchmark"] == name and x["params"]["quick"] is True
        assert x["samples"] and all(isinstance(v, float) for v in x["samples"])
        assert x["device"] != "unknown" and x["commit"] and x["date"] and RUN_ALL["scripts"][name] in x["command"]
    assert "|---|" in r.stdout
