"""Sweeps that lose nothing: the journal, resuming, refusing to mix sweeps; progress in a log."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from ssrlab import bench, journal

REPO = Path(__file__).resolve().parents[1]
TINY = {"width": 32, "height": 24, "shadow_map_size": 128}


def _sweep(folder, cache, **kw):
    args = dict(grid={"layers": [1, 2]}, scenes=["mirror_test"], base=TINY, repeats=1, warmup=0,
                reference="thesis", progress=False, cache_folder=cache, journal=folder)
    args.update(kw)
    return bench.sweep(**args)


def _lines(folder):
    return [json.loads(line) for line in (Path(folder) / journal.JOURNAL_NAME).read_text().splitlines()]


def test_rows_reach_the_journal_and_a_rerun_renders_nothing(tmp_path):
    cache, out = tmp_path / "store", tmp_path / "out"
    rows = _sweep(out, cache)
    lines = _lines(out)
    assert lines[0]["type"] == "sweep" and lines[0]["definition"]["grid"] == {"layers": [1, 2]}
    written = [e for e in lines if e["type"] == "row"]
    assert [e["config_key"] for e in written] == [r["config_key"] for r in rows]
    # Worker and device of every row.
    assert all(r["worker"].endswith(f":{os.getpid()}") and r["gl_renderer"] for r in rows)
    # Run again: every configuration has a row, so nothing renders and the rows are the journal's.
    again = _sweep(out, cache)
    assert [r["timestamp"] for r in again] == [r["timestamp"] for r in rows]
    assert [e["type"] for e in _lines(out)].count("row") == 2


def test_a_cut_journal_runs_only_the_missing_configuration(tmp_path):
    cache, out = tmp_path / "store", tmp_path / "out"
    rows = _sweep(out, cache)
    path = out / journal.JOURNAL_NAME
    header, first, second = path.read_text().splitlines()[:3]
    # A crash while the second row was being written: half a line.
    path.write_text(header + "\n" + first + "\n" + second[: len(second) // 2])
    again = _sweep(out, cache)
    assert again[0]["timestamp"] == rows[0]["timestamp"] and again[0]["config_key"] == rows[0]["config_key"]
    assert again[1]["config_key"] == rows[1]["config_key"]
    keys = [e["config_key"] for e in _lines_lenient(out) if e.get("type") == "row"]
    assert keys == [rows[0]["config_key"], rows[1]["config_key"]]
    assert not again[1]["reference_rendered"], "the reference was in the store already"


def _lines_lenient(folder):
    out = []
    for line in (Path(folder) / journal.JOURNAL_NAME).read_text().splitlines():
        try:
            out.append(json.loads(line))
        except ValueError:
            pass
    return out


def test_another_sweep_or_code_is_refused_unless_forced(tmp_path):
    cache, out = tmp_path / "store", tmp_path / "out"
    rows = _sweep(out, cache)
    with pytest.raises(journal.SweepMismatchError, match="configurations differ"):
        _sweep(out, cache, grid={"layers": [1, 2, 3]})
    header = json.loads((out / journal.JOURNAL_NAME).read_text().splitlines()[0])
    assert set(header["code"]) == {"ssrlab_version", "git_revision", "shaders"}
    mixed = _sweep(out, cache, grid={"layers": [1, 2, 3]}, force_mix=True)
    assert [r["timestamp"] for r in mixed[:2]] == [r["timestamp"] for r in rows]  # kept, not rendered again
    assert [e["type"] for e in _lines(out)].count("mix") == 1
    # Another code version: the journal's header names other code.
    lines = (out / journal.JOURNAL_NAME).read_text().splitlines()
    h = json.loads(lines[0])
    h["code"]["git_revision"] = "0000000"
    (out / journal.JOURNAL_NAME).write_text("\n".join([json.dumps(h), *lines[1:]]) + "\n")
    with pytest.raises(journal.SweepMismatchError, match="code differs.*git_revision"):
        _sweep(out, cache, grid={"layers": [1, 2, 3]})


def test_fronts_never_mix_devices():
    rows = [{"scene": "s", "view": "default", "gl_renderer": "A", "time_frame_ms": 1.0, "thesis_error": 2.0},
            {"scene": "s", "view": "default", "gl_renderer": "B", "time_frame_ms": 0.5, "thesis_error": 1.0},
            {"scene": "s", "view": "default", "gl_renderer": "A", "time_frame_ms": 2.0, "thesis_error": 1.5}]
    fronts = bench.pareto_fronts(rows)
    assert list(fronts) == [("s", "default", "A"), ("s", "default", "B")]
    assert fronts[("s", "default", "A")] == [rows[0], rows[2]]  # B's faster, better row does not hide A's
    with pytest.raises(ValueError, match="2 devices"):
        bench.pareto_front(rows)


def test_cli_resume_needs_a_journal_and_names_it(tmp_path):
    r = subprocess.run([sys.executable, "-m", "ssrlab", "bench", "--resume", str(tmp_path / "none")],
                       capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert r.returncode == 1 and "no sweep journal" in r.stderr


def test_progress_in_a_log_is_lines_without_carriage_returns(tmp_path):
    env = {**os.environ, "SSRLAB_CACHE": str(tmp_path / "cache"), "LP_NUM_THREADS": "1"}
    r = subprocess.run([sys.executable, "-m", "ssrlab", "render", "--scene", "mirror_test", "--width", "32",
                        "--height", "24", "--out", str(tmp_path / "out")], capture_output=True, cwd=tmp_path,
                       env=env, timeout=240)
    assert r.returncode == 0, r.stderr.decode()
    assert b"\r" not in r.stderr and b"\r" not in r.stdout
    lines = [line for line in r.stderr.decode().splitlines() if line.startswith("ssrlab render:")]
    assert len(lines) >= 3 and lines[-1].startswith("ssrlab render: ") and "/" in lines[-1]
    n, total = lines[-1].split(":")[1].split()[0].split("/")
    assert n == total
