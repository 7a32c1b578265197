"""Every benchmark at its full size on one device, in one command.

    python benchmarks/run_all.py [--device auto|gpu|cpu] [--out benchmarks/results] [--only NAME ...] [--quick]
    python benchmarks/run_all.py --registry     # the registry as JSON

A benchmark is named by its script's name, wherever its genre folder (benchmarks/README.md) puts
it: benchmarks/<genre>/<name>.py writes its records under <name> (ssrlab.lab.protocol.Bench), so
committed records and `ssrlab bench compare` / `history` do not depend on the folder.

The docs' results pages (docs/gen_pages.py) are made from the run_all.json files under
benchmarks/results/ and benchmarks/gpu-results/: commit a run's folder to publish it. With
--only, the named benchmarks' entries replace theirs in the device's run_all.json and the others
stay: each entry records its own date, commit and command, which its results page shows.

Runs each benchmark script below as its own process on the chosen device, one after the other
(never side by side: they would time each other), and writes
    <out>/<device>/run_all.json   the device, each benchmark's command, exit status, seconds and output
    <out>/<device>/tables.md      each benchmark's printed tables, for the README
    <out>/<device>/<name>.jsonl   the records of every benchmark written through ssrlab.lab.protocol
                                  (appended run after run: `ssrlab bench compare` reads them)
<device> is a slug of the renderer string (e.g. nvidia-h100-80gb-hbm3, llvmpipe-llvm-15-0-6-256-bits).
--quick runs every benchmark at a reduced size (a smoke run of this script, not figures to quote).
On a machine with a GPU, `--device gpu` fails at once when the EGL device cannot be opened.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
# Every script of a genre folder, by name (its records' benchmark name): run_all runs the
# registered ones below, wherever they sit.
SCRIPTS = {p.stem: p for p in sorted(HERE.glob("*/*.py")) if p.name != "__init__.py"}

# name: (arguments at full size, arguments at --quick size)
BENCHMARKS = {
    "first_render": ([], ["--repeats", "3", "--scenes", "spheres_and_boxes"]),
    "peel_layers": ([], ["--width", "160", "--height", "90", "--repeats", "2", "--layers", "1", "2"]),
    "trace_methods": ([], ["--width", "160", "--height", "90", "--repeats", "2"]),
    "reference_speed": ([], ["--width", "160", "--height", "90", "--rays", "16"]),
    "accuracy": ([], []),
    "mitsuba_crosscheck": ([], ["--width", "160", "--height", "90", "--spp", "64", "--frame-sizes", "96x54",
                                "--repeats", "2"]),
    "glossy_methods": ([], ["--width", "160", "--height", "90", "--repeats", "2", "--reference-rays", "16"]),
    "temporal": ([], ["--width", "96", "--height", "64", "--frames", "4"]),
    "skip": ([], ["--width", "160", "--height", "90", "--repeats", "2", "--reference-rays", "32", "--error-seeds", "1"]),
    "hybrid": (["--sizes", "320x180,640x360"], ["--sizes", "96x54", "--repeats", "2"]),
    "hybrid_confidence": (["--baseline", "e417b81"], ["--baseline", "e417b81", "--sizes", "96x54",
                                                      "--timing-sizes", "96x54", "--repeats", "2"]),
    "svgf": ([], ["--width", "96", "--height", "64", "--frames", "4", "--repeats", "1"]),
    "depth_precision": ([], ["--width", "96", "--height", "64"]),
    "memory": ([], ["--renders", "50"]),
    # --quick leaves docs/images alone: the README's figures are the full scale's
    "thesis_findings": (["--scale", "full"], ["--scale", "small", "--figures", ""]),
    "roofline": ([], ["--quick"]),
    "frame_breakdown": ([], ["--width", "96", "--height", "64", "--repeats", "2", "--scenes", "hall"]),
    "readback": ([], ["--sizes", "96x64", "--repeats", "3"]),
    "trace_parts": ([], ["--width", "96", "--height", "64", "--repeats", "2"]),
    "occlusion": ([], ["--width", "96", "--height", "54", "--repeats", "2", "--reference-rays", "16"]),
    "metric_cost": ([], ["--repeats", "1"]),
    "raster_floor": (["--scenes", "hall", "spheres_and_boxes", "box_stack", "2CylinderEngine"], ["--width", "160", "--height", "90", "--repeats", "3"]),
    "deep_gbuffer": ([], ["--width", "160", "--height", "90", "--repeats", "3", "--layers", "1", "8"]),
    "construction_switch": ([], ["--width", "160", "--height", "90", "--repeats", "2"]),
    "min_separation": ([], ["--width", "96", "--height", "54", "--frames", "2", "--reference-rays", "8"]),
    "input_fetch": (["--width", "640", "--height", "360"], ["--width", "96", "--height", "64", "--repeats", "2", "--scenes", "hall"]),
    "layers_vs_rays": ([], ["--width", "96", "--height", "54", "--repeats", "3", "--reference-rays", "8"]),
    "shadows": ([], ["--width", "96", "--height", "54", "--repeats", "2", "--map-size", "256"]),
    "emissive_texture": ([], ["--width", "96", "--height", "54", "--repeats", "2"]),
    "specular_texture": (["--base-texture"], ["--width", "96", "--height", "54", "--repeats", "2"]),
    "scene_updates": ([], ["--width", "96", "--height", "54", "--repeats", "2", "--suzannes", "10", "--moved", "1", "5"]),
    "temporal_motion": ([], ["--width", "96", "--height", "54", "--frames", "8", "--moving", "4", "--reference-rays", "8",
                             "--repeats", "2", "--suzannes", "10"]),
    "render_estimate": ([], ["--width", "96", "--height", "54", "--instances", "100", "--stacked", "25"]),
}

# name: the arguments of its smoke run (tests/test_bench_records.py): the smallest size at which the
# script still measures and records every figure it prints, a few seconds on llvmpipe. Every
# benchmark registered above has one: each writes records and takes --device (protocol.arguments).
SMOKE = {
    "first_render": ["--width", "32", "--height", "18", "--repeats", "1", "--rounds", "1", "--scenes", "hall"],
    "peel_layers": ["--width", "32", "--height", "18", "--repeats", "1", "--layers", "1", "2", "--scenes", "hall"],
    "trace_methods": ["--width", "32", "--height", "18", "--repeats", "1", "--scenes", "hall"],
    "reference_speed": ["--width", "32", "--height", "18", "--rays", "2", "--repeats", "1", "--scenes",
                        "spheres_and_boxes", "--no-mitsuba", "--tracers", "cpu", "glsl"],
    "accuracy": ["--scenes", "hall"],
    "mitsuba_crosscheck": ["--width", "32", "--height", "18", "--spp", "4", "--roughness", "0.5", "--frame-sizes",
                           "32x18", "--repeats", "1"],
    "glossy_methods": ["--width", "32", "--height", "18", "--repeats", "1", "--reference-rays", "4", "--scenes", "hall"],
    "temporal": ["--width", "32", "--height", "18", "--frames", "2"],
    "skip": ["--width", "32", "--height", "18", "--repeats", "1", "--reference-rays", "4", "--error-seeds", "1",
             "--shares", "0", "10", "--adaptive-mixes", "mirrors", "--adaptive-methods", "hiz", "--adaptive-reuse", "1"],
    "hybrid": ["--scenes", "hall", "--width", "32", "--height", "18", "--repeats", "1", "--reference-rays", "4"],
    "hybrid_confidence": ["--sizes", "160x90", "--timing-sizes", "32x18", "--repeats", "1"],
    "svgf": ["--width", "32", "--height", "18", "--frames", "2", "--repeats", "1"],
    "depth_precision": ["--width", "32", "--height", "18"],
    "memory": ["--renders", "3", "--warmup", "1"],
    "roofline": ["--quick"],
    "frame_breakdown": ["--width", "32", "--height", "18", "--repeats", "1", "--scenes", "hall"],
    "readback": ["--sizes", "32x18", "--repeats", "1"],
    "trace_parts": ["--width", "32", "--height", "18", "--repeats", "1", "--scenes", "hall"],
    "occlusion": ["--width", "32", "--height", "18", "--repeats", "1", "--reference-rays", "2", "--scenes", "hall",
                  "--roughness", "0.2", "--methods", "cone"],
    "metric_cost": ["--repeats", "1", "--sizes", "64x48"],
    "raster_floor": ["--width", "32", "--height", "18", "--repeats", "1", "--scenes", "hall"],
    "deep_gbuffer": ["--width", "32", "--height", "18", "--repeats", "1", "--layers", "1", "2", "--scenes", "hall"],
    "construction_switch": ["--width", "32", "--height", "18", "--repeats", "1"],
    "min_separation": ["--width", "32", "--height", "18", "--frames", "2", "--reference-rays", "2", "--separations",
                       "0.2", "--scenes", "hall"],
    "input_fetch": ["--width", "32", "--height", "18", "--repeats", "1", "--scenes", "hall"],
    "layers_vs_rays": ["--width", "32", "--height", "18", "--repeats", "3", "--reference-rays", "2", "--scenes", "hall",
                       "--deep-gbuffer", "peel"],
    "shadows": ["--width", "32", "--height", "18", "--repeats", "1", "--map-size", "64"],
    "emissive_texture": ["--width", "32", "--height", "18", "--repeats", "1"],
    "specular_texture": ["--width", "32", "--height", "18", "--repeats", "1"],
    "scene_updates": ["--width", "32", "--height", "18", "--repeats", "1", "--suzannes", "4", "--moved", "1"],
    "temporal_motion": ["--width", "32", "--height", "18", "--frames", "3", "--moving", "2", "--reference-rays", "2",
                        "--repeats", "1", "--suzannes", "4", "--sequences", "sphere over mirror"],
    "render_estimate": ["--width", "32", "--height", "18", "--instances", "2", "--stacked", "2", "--rounds", "1"],
    # one notebook: the others record the same kinds of figure; nothing written into the checkout
    # (docs/images' figures, results/notebooks' executed copies)
    "thesis_findings": ["--scale", "small", "--only", "hiz_vs_linear", "--figures", "", "--executed", ""],
}


def script_path(name: str) -> str:
    """The benchmark's script as a person types it from the repository's root."""
    return SCRIPTS[name].relative_to(HERE.parent).as_posix()


def git_commit() -> str:
    """The checkout's commit, "+dirty" when it has uncommitted changes (what the figures come from)."""
    from ssrlab.lab.records import git_commit as commit_of

    return commit_of(HERE)


def slug(text: str) -> str:
    from ssrlab.lab.records import slug as slug_of  # the records' folder name: one rule

    return slug_of(text)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--device", default="auto", choices=("auto", "gpu", "cpu"))
    ap.add_argument("--out", default=str(HERE / "results"))
    ap.add_argument("--only", nargs="+", choices=sorted(BENCHMARKS))
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--registry", action="store_true",
                    help="print the registry (full, quick and smoke arguments, every script's path) "
                         "as JSON and exit")
    args = ap.parse_args()
    if args.registry:  # what tests/test_bench_records.py runs: a test imports no script by path
        print(json.dumps({"benchmarks": BENCHMARKS, "smoke": SMOKE,
                          "scripts": {name: script_path(name) for name in SCRIPTS}}))
        return 0

    import ssrlab
    from ssrlab.lab.records import QUICK_ENV, RECORDS_ENV, read_records

    info = ssrlab.Renderer(args.device).info  # fails here, before any benchmark, without the device
    folder = Path(args.out) / slug(f"{info['renderer']}")
    folder.mkdir(parents=True, exist_ok=True)
    print(f"device: {info['renderer']} ({info['device']}), {info['vendor']}, OpenGL {info['gl_version']}")
    started, commit = datetime.datetime.now(datetime.timezone.utc).isoformat(), git_commit()
    command = "python benchmarks/run_all.py " + " ".join(sys.argv[1:])
    results = {"device": info, "started": started, "commit": commit, "command": command,
               "quick": args.quick, "python": sys.version, "ssrlab": ssrlab.__version__, "benchmarks": {}}
    earlier = folder / "run_all.json"
    if args.only and earlier.is_file():  # the other benchmarks' entries stay, each with its own provenance
        old = json.loads(earlier.read_text())
        for name, entry in old.get("benchmarks", {}).items():
            for key in ("started", "commit", "quick"):
                entry.setdefault(key, old.get(key))
            entry.setdefault("run_command", old.get("command"))
            results["benchmarks"][name] = entry
    names = args.only or list(BENCHMARKS)
    for name in names:
        if name not in SCRIPTS:
            print(f"[run_all] {name}: no {name}.py in a genre folder here, skipped")
            continue
        script = SCRIPTS[name]
        full, quick = BENCHMARKS[name]
        extra = quick if args.quick else full
        cmd = [sys.executable, str(script), *extra, "--device", args.device]
        print(f"[run_all] {' '.join(cmd[1:])}", flush=True)
        t0 = time.perf_counter()
        # Every benchmark converted to the protocol appends its records to <folder>/<name>.jsonl.
        # The records carry this checkout's commit, whichever copy of ssrlab the scripts import.
        env = {**os.environ, "PYTHONUNBUFFERED": "1", RECORDS_ENV: str(folder), QUICK_ENV: "1" if args.quick else "0",
               "SSRLAB_COMMIT": os.environ.get("SSRLAB_COMMIT", commit)}
        before = len(read_records(folder / f"{name}.jsonl")) if (folder / f"{name}.jsonl").is_file() else 0
        p = subprocess.run(cmd, capture_output=True, text=True, env=env)
        seconds = time.perf_counter() - t0
        print(p.stdout, end="")
        if p.returncode:
            print(p.stderr[-4000:], file=sys.stderr)
        results["benchmarks"][name] = {"command": " ".join(["python", script_path(name), *cmd[2:]]),
                                       "exit": p.returncode, "seconds": round(seconds, 1), "output": p.stdout,
                                       "stderr_tail": p.stderr[-4000:], "started": started, "commit": commit,
                                       "quick": args.quick, "run_command": command,
                                       "records": (len(read_records(folder / f"{name}.jsonl")) - before
                                                   if (folder / f"{name}.jsonl").is_file() else 0)}
        (folder / "run_all.json").write_text(json.dumps(results, indent=1))
    md = [f"# Benchmarks on {info['renderer']}", "",
          f"{info['vendor']}, OpenGL {info['gl_version']}, device `{info['device']}`; "
          f"{results['started'][:16]} UTC; commit {results['commit']}; `{results['command']}`", ""]
    for name, r in results["benchmarks"].items():
        md += [f"## {name} ({r['seconds']:.0f} s, exit {r['exit']})", "", f"`{r['command']}`", "", "```",
               r["output"].rstrip(), "```", ""]
    (folder / "tables.md").write_text("\n".join(md))
    print(f"[run_all] wrote {folder / 'run_all.json'} and {folder / 'tables.md'}")
    return 1 if any(r["exit"] for r in results["benchmarks"].values()) else 0


if __name__ == "__main__":
    sys.exit(main())
