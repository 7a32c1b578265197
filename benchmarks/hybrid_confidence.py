"""The hybrid's confidence test (docs/guide/hybrid.md): the screen hits it keeps on another object
than the one the ray meets, the share of rays it sends to the BVH, the hybrid's PSNR against the
physical reference and what the test costs, this checkout's shaders beside a baseline's.

    python benchmarks/hybrid_confidence.py [--baseline COMMIT] [--sizes 160x90,320x180,640x360,1280x720]
                                           [--timing-sizes 320x180,640x360] [--repeats 5] [--device auto]

Every frame is fallback "bvh" with its confidence test (the default fallback_confidence), one mirror
ray per pixel, default settings but the tracer and the layer count.

Counts: for each scene (crosscheck: the Mitsuba cross-check's mirror floor,
ssrlab.crosscheck.crosscheck_scene(0); hall with a mirror floor; box_stack), size, tracer (hiz,
linear) and layer count (1, 3): 'wrong', the rays whose screen hit was kept at full strength on
another G-buffer object than the one the per-ray reference (the very rays, traced against the
triangles from the exact surface point) meets (ssrlab.lab.hybrid.wrong_object_hits); 'kept' the
share of rays screen space kept, 'bvh' the share the BVH traced and hit (Frame.fallback_stats).

PSNR: the cross-check's floor pixels' reflection against the converged physical reference
(viewer "ray", traced shadows) at each timing size, per tracer; the goal is 40 dB.

Cost: the GPU ms of hiz_build, the trace pass, fallback_bvh and the whole frame, median [min, max]
of --repeats renders after 2 warm-ups, one layer, per scene, timing size and tracer; with a
baseline, both sides rendered alternately in one process (each its own Renderer) and the paired
ratio current / baseline of the frame, with ssrlab.lab.timing's verdict.

--baseline COMMIT: the shaders of that commit (git archive of its shaders/) run by this build. The
build's side of the sight map only allocates it and defines its construction (HIZ_SIGHT), which a
baseline's shaders ignore, so the two sides differ by their shaders alone.
"""

from __future__ import annotations

import statistics
import subprocess
import tarfile
import tempfile
from io import BytesIO
from pathlib import Path

import numpy as np

import ssrlab
from common import benchmark_arguments
from ssrlab.crosscheck import crosscheck_scene
from ssrlab.lab import hybrid
from ssrlab.lab.protocol import Bench, device_header
from ssrlab.lab.timing import median_range, paired, verdict
from ssrlab.metrics import psnr

REPO = Path(__file__).resolve().parents[1]
SCENES = {
    "crosscheck": lambda: crosscheck_scene(0.0),
    "hall": lambda: ssrlab.scenes.hall(floor_roughness=0.0),
    "box_stack": lambda: ssrlab.scenes.box_stack(),
}
METHODS = ("hiz", "linear")
LAYERS = (1, 3)


def sizes(text: str) -> list[tuple[int, int]]:
    return [tuple(int(v) for v in s.split("x")) for s in text.split(",") if s]


def baseline_shaders(commit: str, folder: Path) -> Path:
    """The shaders/ folder of `commit`, extracted under `folder`."""
    data = subprocess.run(["git", "-C", str(REPO), "archive", "--format=tar", commit, "shaders"],
                          check=True, capture_output=True).stdout
    with tarfile.open(fileobj=BytesIO(data)) as tar:
        tar.extractall(folder, filter="data")
    return folder / "shaders"


def settings(size, method, layers=1) -> ssrlab.Settings:
    return ssrlab.Settings(width=size[0], height=size[1], method=method, layers=layers, fallback="bvh")


def main(argv=None) -> int:
    ap = benchmark_arguments(__doc__, repeats=5, settings=False)
    ap.add_argument("--baseline", metavar="COMMIT", help="also run the shaders of this commit")
    ap.add_argument("--sizes", default="160x90,320x180,640x360,1280x720", help="sizes of the counts")
    ap.add_argument("--timing-sizes", default="320x180,640x360", help="sizes of the PSNR and the cost")
    args = ap.parse_args(argv)
    current = ssrlab.Renderer(args.device)
    print(device_header(current), flush=True)
    bench = Bench("hybrid_confidence", args, current)
    with tempfile.TemporaryDirectory(prefix="hybrid_confidence_") as tmp:
        sides = {"current": current}
        if args.baseline:
            sides = {"baseline": ssrlab.Renderer(args.device, shader_dir=baseline_shaders(args.baseline, Path(tmp))),
                     "current": current}
            print(f"baseline: the shaders of {args.baseline}; current: this checkout's", flush=True)
        scenes = {name: make() for name, make in SCENES.items()}
        wrong_total = {side: 0 for side in sides}

        print("\nkept screen hits on another object than the per-ray reference's ('wrong'), the share of rays "
              "kept on screen and the share the BVH traced and hit" +
              (", baseline -> current" if len(sides) > 1 else ""))
        print(f"{'scene':11s} {'size':>9s} {'tracer':6s} {'layers':>6s} {'wrong':>13s} {'kept':>15s} {'bvh':>15s}")
        for name, scene in scenes.items():
            for size in sizes(args.sizes):
                for method in METHODS:
                    for layers in LAYERS:
                        st = settings(size, method, layers)
                        got = {}
                        for side, r in sides.items():
                            o = hybrid.wrong_object_hits(r, scene, st, against_bvh=False)
                            got[side] = o
                            wrong_total[side] += o["wrong"]
                            params = dict(scene=name, width=size[0], height=size[1], method=method, layers=layers,
                                          side=side, baseline=args.baseline)
                            bench.recorder.add(params, "wrong_kept_hits", "rays", [o["wrong"]], better="lower")
                            bench.recorder.add(params, "bvh_share", "share", [o["bvh"]], better="lower")
                            del o["frame"], o["truth"]

                        def cell(key, fmt):
                            return " -> ".join(format(got[s][key], fmt) for s in sides)
                        print(f"{name:11s} {size[0]:>4d}x{size[1]:<4d} {method:6s} {layers:>6d} {cell('wrong', 'd'):>13s} "
                              f"{cell('screen', '.3f'):>15s} {cell('bvh', '.3f'):>15s}", flush=True)
        for side in sides:
            print(f"{side}: {wrong_total[side]} kept screen hits on another object in all")

        print("\ncrosscheck floor pixels' reflection PSNR against the converged physical reference (goal >= 40 dB)")
        scene = scenes["crosscheck"]
        for size in sizes(args.timing_sizes):
            for method in METHODS:
                cells = []
                for side, r in sides.items():
                    f = r.render(scene, settings=settings(size, method))
                    floor = f.gbuffer.object_id[0] == 0
                    truth = f.reference("converged", rays=1).reflection
                    db = psnr(f.reflection, truth, mask=floor)
                    bench.recorder.add(dict(scene="crosscheck", width=size[0], height=size[1], method=method, side=side,
                                            baseline=args.baseline), "psnr_physical", "dB", [db], better="higher")
                    cells.append(f"{db:.2f} dB")
                print(f"  {size[0]}x{size[1]} {method:6s} {' -> '.join(cells)}", flush=True)

        print(f"\nGPU ms, median [min, max] of {args.repeats} renders after 2 warm-ups, one layer" +
              (", baseline and current alternately; frame ratio: current / baseline per round" if len(sides) > 1 else ""))
        for name, scene in scenes.items():
            for size in sizes(args.timing_sizes):
                for method in METHODS:
                    st = settings(size, method)
                    parts = ("hiz_build", f"trace_{method}", "fallback_bvh", "total")
                    times = {side: {p: [] for p in parts} for side in sides}
                    for rnd in range(2 + args.repeats):
                        order = list(sides.items()) if rnd % 2 == 0 else list(reversed(sides.items()))
                        for side, r in order:
                            t = r.render(scene, settings=st).timings
                            if rnd >= 2:
                                for p in parts:
                                    if p in t:
                                        times[side][p].append(float(t[p]))
                    print(f"  {name} {size[0]}x{size[1]} {method}")
                    for side in sides:
                        cells = []
                        for p in parts:
                            if times[side][p]:
                                m, lo, hi = median_range(times[side][p])
                                cells.append(f"{p} {m:.1f} [{lo:.1f}, {hi:.1f}]")
                                bench.recorder.add(dict(scene=name, width=size[0], height=size[1], method=method,
                                                        side=side, baseline=args.baseline, part=p),
                                                   "gpu_ms", "ms", times[side][p], better="lower")
                        print(f"    {side:8s} " + "; ".join(cells))
                    if len(sides) > 1:
                        b, c = times["baseline"]["total"], times["current"]["total"]
                        ratio = statistics.median(paired(c, b))
                        print(f"    frame current / baseline {ratio:.2f}x "
                              f"({verdict(median_range(b), median_range(c))})", flush=True)
    return 1 if wrong_total["current"] else 0


if __name__ == "__main__":
    raise SystemExit(main())
