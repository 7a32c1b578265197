"""A short, fixed-seed run of the glTF fuzzer (benchmarks/fuzzing/fuzz_gltf.py): its mutants of the
sample models and the hostile reproducers must give SceneErrors or finite 32x24 renders,
never another exception, a crash, a hang or a non-finite image."""

import json
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def test_fuzzer_short_run_has_no_findings(tmp_path):
    out = tmp_path / "fuzz"
    proc = subprocess.run(
        [sys.executable, str(REPO / "benchmarks" / "fuzzing" / "fuzz_gltf.py"), "--seed", "3", "--max-mutants", "400",
         "--minutes", "0.75", "--timeout", "30", "--out", str(out)],
        capture_output=True, text=True, timeout=300)
    summary = json.loads((out / "summary.json").read_text())
    findings = sorted(p.name for p in out.glob("finding_*"))
    assert proc.returncode == 0 and summary["findings"] == 0, (proc.stdout[-3000:], proc.stderr[-3000:], findings)
    assert summary["mutants"] >= 30, summary  # the run did real work
    assert summary["refused"] > 0 and summary["rendered"] > 0, summary  # both paths exercised


def test_fuzzer_records_crashes_and_hangs(tmp_path):
    """The harness itself: a child killed by SIGSEGV and a child that stops answering are each
    saved as a finding (with the exit status / stack), and fuzzing goes on after them."""
    out = tmp_path / "fuzz"
    proc = subprocess.run(
        [sys.executable, str(REPO / "benchmarks" / "fuzzing" / "fuzz_gltf.py"), "--seed", "3", "--max-mutants", "5",
         "--timeout", "3", "--selftest", "crash", "none", "hang", "--out", str(out)],
        capture_output=True, text=True, timeout=300)
    summary = json.loads((out / "summary.json").read_text())
    assert proc.returncode == 1 and summary["findings"] == 2 and summary["mutants"] == 5, (summary, proc.stdout)
    crash = json.loads(next(out.glob("finding_*_crash")).joinpath("info.json").read_text())
    hang = json.loads(next(out.glob("finding_*_hang")).joinpath("info.json").read_text())
    assert crash["exit_status"] == -11 and "SIGSEGV" in crash["message"]
    assert "Segmentation fault" in crash["stderr"] or "Fatal Python error" in crash["stderr"]
    assert "no answer" in hang["message"] and "child_main" in hang["stderr"]  # faulthandler's stack
