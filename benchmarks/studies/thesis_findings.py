"""Runs the three paper-reproduction notebooks and records every finding beside its figures.

    python benchmarks/studies/thesis_findings.py [--scale full|small] [--taa thesis|off] [--figures docs/images]
                                                 [--executed results/notebooks] [--device auto|gpu|cpu]

Each notebook (notebooks/*.ipynb) runs its experiment from ssrlab.experiments at the given
scale (full: 640x360, median of 5 runs after 2 warm-ups, 256-ray converged references; about
ten minutes on llvmpipe), saves its figures into --figures (none with --figures ""), and ends
with its table of the paper's findings and ours. Executed copies of the notebooks go to
--executed (none with --executed ""). --device pins the notebooks' kernels to a device ($SSRLAB_DEVICE) and is the
device the records name.

Every figure is a record (ssrlab.lab.protocol), benchmark "thesis_findings":
  - each sweep row of each experiment (params: experiment, sweep, reference, scene and the
    setting the sweep varies): thesis_error (and psnr, higher is better) against that reference,
    one value (with TAA, the mean over the sequence's timed frames); the frame's, the
    reflections' and the trace's GPU ms, every timed run a sample (the sweep row's samples; the
    trace's, per run, the sum of its parts), with the spread beside it (spread: min, max, iqr;
    params: timed_runs);
  - each finding (params: experiment, finding, source): metric "agreement", 1 agree, 0.5 partly,
    0 disagree, NaN where the timings cannot bear a verdict (ssrlab.lab.timing.timing_doubt),
    with the claim, our figures and the verdict, computed by ssrlab.experiments, beside it.
The tables printed are rendered from those records: the findings (records.markdown of the
finding records' fields) and the figures (records.table).

--taa: the thesis's two experiments run with its temporal anti-aliasing (seed 000, 2.5), as
the thesis measured them ("thesis", the default: sequences of the static camera, see
ssrlab.experiments), or on single frames without it ("off"); hiz_vs_linear always runs single
frames. The TAA cost lines the notebooks print (the reproject and taa passes' share of the
frame) are printed too.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
import time
from pathlib import Path

import nbclient
import nbformat

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import open_renderer  # noqa: E402
from ssrlab.lab import records  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402

NOTEBOOKS = ["thesis_layers", "thesis_downscale_rays_stride", "hiz_vs_linear"]
AGREEMENT = {"agree": 1.0, "partly": 0.5, "disagree": 0.0}  # anything else: no verdict (NaN)
# The notebook's experiment, written out by a cell run after the notebook's own (and left out of
# the executed copy): its findings and its sweep rows, as ssrlab.experiments made them.
DUMP_ENV = "SSRLAB_FINDINGS_DUMP"
DUMP_CELL = f"""import dataclasses as _dc, json as _json, os as _os
with open(_os.environ["{DUMP_ENV}"], "w") as _f:
    _json.dump({{"name": exp.name, "scale": exp.scale, "taa": exp.taa, "device": exp.device,
                "findings": [_dc.asdict(x) for x in exp.findings], "rows": exp.rows}}, _f, default=str)
"""
# Row columns recorded: (metric, unit, better).
ERRORS = {"thesis_error": ("thesis_error", "", None), "psnr": ("psnr", "dB", "higher")}
TIMES = {"time_frame_ms": "frame", "time_reflections_ms": "reflections"}
TRACE_COLUMNS = ("gpu_trace_linear_ms", "gpu_trace_hiz_ms", "gpu_hiz_build_ms")  # experiments.trace_ms


def varied(rows: list[dict]) -> list[str]:
    """The settings columns (s_*) whose value differs between a sweep's rows: what it sweeps."""
    keys = [k for k in rows[0] if k.startswith("s_")] if rows else []
    return [k for k in keys if len({json.dumps(r.get(k)) for r in rows}) > 1]


def record_experiment(bench: Bench, exp: dict, seconds: float) -> None:
    base = {"experiment": exp["name"], "scale": exp["scale"], "taa": exp["taa"]}
    for key, rows in exp["rows"].items():
        swept = varied(rows)
        for row in rows:
            params = {**base, "sweep": key, "reference": row.get("reference"), "scene": row["scene"],
                      "setting": ", ".join(f"{k[2:]}={row[k]:g}" if isinstance(row[k], float) else f"{k[2:]}={row[k]}"
                                           for k in swept),
                      "width": row.get("s_width"), "height": row.get("s_height"), "timed_runs": row.get("repeats")}
            for column, (metric, unit, better) in ERRORS.items():
                if row.get(column) is not None:
                    bench.record(params, metric, unit, [row[column]], **({"better": better} if better else {}))
            for column, metric in TIMES.items():
                if row.get(column) is not None:
                    bench.record(params, metric, "ms", row.get("samples", {}).get(column) or [row[column]],
                                 spread={s: row.get(column + "_" + s) for s in ("min", "max", "iqr")})
            parts = [row.get("samples", {}).get(c) for c in TRACE_COLUMNS if row.get(c) is not None]
            if parts and all(parts) and len({len(p) for p in parts}) == 1:
                bench.record(params, "trace", "ms", [float(sum(x)) for x in zip(*parts)])  # per run, the parts summed
            elif parts:
                trace = [row[c] for c in TRACE_COLUMNS if row.get(c) is not None]
                bench.record(params, "trace", "ms", [sum(trace)])  # each part's median, summed
    for i, f in enumerate(exp["findings"], 1):
        bench.record({**base, "finding": i, "source": f["source"]}, "agreement", "",
                     [AGREEMENT.get(f["verdict"], math.nan)], better="higher", claim=f["claim"], ours=f["ours"],
                     verdict=f["verdict"], seconds=round(seconds, 1), device_line=exp["device"])


def findings_table(recs: list[dict]) -> str:
    """The findings, one row per finding record: the claim, our figures and the verdict."""
    return records.markdown(["finding (source)", "ours", "verdict"],
                            [[f"{r['claim']} ({r['params']['source']})", r["ours"], f"**{r['verdict']}**"]
                             for r in recs])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scale", default="full", choices=("full", "small"))
    ap.add_argument("--taa", default="thesis", choices=("thesis", "off"),
                    help="TAA of the thesis's experiments (default: the thesis's, as it measured them)")
    ap.add_argument("--figures", default=str(ROOT / "docs" / "images"), help='folder of the figures ("": none)')
    ap.add_argument("--executed", default=str(ROOT / "results" / "notebooks"), help='folder of the executed '
                    'notebooks ("": none)')
    ap.add_argument("--only", nargs="+", choices=NOTEBOOKS, default=NOTEBOOKS, help="run only these notebooks")
    ap.add_argument("--device", default="auto", choices=("auto", "gpu", "cpu"))
    ap.add_argument("--records", metavar="FOLDER", help="append this run's records to FOLDER/thesis_findings.jsonl "
                    f"(default: ${records.RECORDS_ENV} where set, else none are written)")
    ap.add_argument("--records-quick", action="store_true", help="mark the records quick: true")
    args = ap.parse_args()
    renderer = open_renderer(args)  # the device line, and the device the records name
    bench = Bench("thesis_findings", args, renderer, repeats=1)
    os.environ["SSRLAB_NOTEBOOK_SCALE"] = args.scale
    os.environ["SSRLAB_NOTEBOOK_OUT"] = args.figures
    os.environ["SSRLAB_NOTEBOOK_TAA"] = args.taa
    if args.device != "auto":
        os.environ["SSRLAB_DEVICE"] = args.device  # the kernels' Renderer("auto") opens this one
    os.environ.setdefault("MPLBACKEND", "Agg")
    if args.executed:
        Path(args.executed).mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.only:
            start = time.time()
            nb = nbformat.read(ROOT / "notebooks" / f"{name}.ipynb", as_version=4)
            nb.cells.append(nbformat.v4.new_code_cell(DUMP_CELL))
            os.environ[DUMP_ENV] = str(Path(tmp) / f"{name}.json")  # the kernel inherits the environment
            nbclient.NotebookClient(nb, timeout=3600, kernel_name="python3",
                                    resources={"metadata": {"path": str(ROOT)}}).execute()
            nb.cells.pop()
            if args.executed:
                nbformat.write(nb, Path(args.executed) / f"{name}.ipynb")
            exp = json.loads((Path(tmp) / f"{name}.json").read_text())
            seconds = time.time() - start
            record_experiment(bench, exp, seconds)
            outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])]
            stdout = [line for o in outputs if o.get("name") == "stdout" for line in o.get("text", "").splitlines()]
            print(f"## {name} ({args.scale} scale, {seconds:.0f} s)")
            print(next((line for line in stdout if line.startswith("device:")), ""))
            for line in stdout:
                if line.startswith("TAA cost"):
                    print(line)
            print()
            print(findings_table(bench.find("agreement", experiment=exp["name"])))
            print()
            figures = [r for r in bench.recorder.records if r["params"]["experiment"] == exp["name"]
                       and r["metric"] != "agreement"]
            bench.print_table(figures, rows=("sweep", "scene", "setting"),
                              order=["thesis_error", "psnr", "frame", "reflections", "trace"], digits=4)
            print()


if __name__ == "__main__":
    main()
