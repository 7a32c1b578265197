"""A short, fixed-seed run of the glTF fuzzer (benchmarks/fuzz_gltf.py): its mutants of the
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
        [sys.executable, str(REPO / "benchmarks" / "fuzz_gltf.py"), "--seed", "3", "--max-mutants", "400",
         "--minutes", "0.75", "--timeout", "30", "--device", "cpu", "--out", str(out)],
        capture_output=True, text=True, timeout=300)
    summary = json.loads((out / "summary.json").read_text())
    findings = sorted(p.name for p in out.glob("finding_*"))
    assert proc.returncode == 0 and summary["findings"] == 0, (proc.stdout[-3000:], proc.stderr[-3000:], findings)
    assert summary["mutants"] >= 30, summary  # the run did real work
    assert summary["refused"] > 0 and summary["rendered"] > 0, summary  # both paths exercised
