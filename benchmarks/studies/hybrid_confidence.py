"""The hybrid's confidence test (docs/guide/hybrid.md): the screen hits it keeps on another object
than the one the ray meets, the share of rays it sends to the BVH, the hybrid's PSNR against the
physical reference and what the test costs, this checkout's shaders beside a baseline's.

    python benchmarks/studies/hybrid_confidence.py [--baseline COMMIT] [--sizes 160x90,320x180,640x360,1280x720]
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

Cost: the GPU ms of hiz_build, the trace pass, fallback_bvh and the whole frame, --repeats rounds
after the protocol's warm-up rounds, one layer, per scene, timing size and tracer; with a
baseline, both sides rendered alternately in one process (each its own Renderer), and the table
gives the per-round ratio current / baseline with records.figure_verdict's verdict.
Every figure is a record; the tables are rendered from the records.

--baseline COMMIT: the shaders of that commit (git archive of its shaders/) run by this build. The
build's side of the sight map only allocates it and defines its construction (HIZ_SIGHT), which a
baseline's shaders ignore, so the two sides differ by their shaders alone.
"""

from __future__ import annotations

import sys
import subprocess
import tarfile
import tempfile
from io import BytesIO
from pathlib import Path

import ssrlab

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments  # noqa: E402
from ssrlab.crosscheck import crosscheck_scene  # noqa: E402
from ssrlab.lab import hybrid  # noqa: E402
from ssrlab.lab.protocol import Bench, device_header  # noqa: E402
from ssrlab.metrics import psnr  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
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

        counts = []
        for name, scene in scenes.items():
            for size in sizes(args.sizes):
                for method in METHODS:
                    for layers in LAYERS:
                        st = settings(size, method, layers)
                        for side, r in sides.items():
                            o = hybrid.wrong_object_hits(r, scene, st, against_bvh=False)
                            wrong_total[side] += o["wrong"]
                            params = dict(scene=name, width=size[0], height=size[1], method=method, layers=layers,
                                          side=side, baseline=args.baseline)
                            counts.append(bench.record(params, "wrong_kept_hits", "rays", [o["wrong"]], better="lower"))
                            counts.append(bench.record(params, "kept_share", "share", [o["screen"]]))
                            counts.append(bench.record(params, "bvh_share", "share", [o["bvh"]], better="lower"))
                            del o["frame"], o["truth"]
                print(f"  counts of {name} at {size[0]}x{size[1]}: done", flush=True)
        print("\nkept screen hits on another object than the per-ray reference's (wrong_kept_hits), the share of rays "
              "kept on screen and the share the BVH traced and hit")
        bench.print_table(counts, rows=("scene", "width", "height", "method", "layers", "side"), digits=3, note=False)
        for side in sides:
            print(f"{side}: {wrong_total[side]} kept screen hits on another object in all")

        scene = scenes["crosscheck"]
        psnrs = []
        for size in sizes(args.timing_sizes):
            for method in METHODS:
                for side, r in sides.items():
                    f = r.render(scene, settings=settings(size, method))
                    floor = f.gbuffer.object_id[0] == 0
                    truth = f.reference("converged", rays=1).reflection
                    db = psnr(f.reflection, truth, mask=floor)
                    psnrs.append(bench.record(dict(scene="crosscheck", width=size[0], height=size[1], method=method,
                                                   side=side, baseline=args.baseline), "psnr_physical", "dB", [db],
                                              better="higher"))
        print("\ncrosscheck floor pixels' reflection PSNR against the converged physical reference (goal >= 40 dB)")
        bench.print_table(psnrs, rows=("width", "height", "method"), columns="side", note=False)
        low = min(x["samples"][0] for x in psnrs if x["params"]["side"] == "current")
        print(f"lowest PSNR of the current shaders {low:.2f} dB: goal >= 40 dB {'met' if low >= 40 else 'not met'}")

        timing = []
        for name, scene in scenes.items():
            for size in sizes(args.timing_sizes):
                for method in METHODS:
                    st = settings(size, method)
                    parts = ("hiz_build", f"trace_{method}", "fallback_bvh", "total")
                    times = bench.rounds({side: (lambda r=r: r.render(scene, settings=st).timings)
                                          for side, r in sides.items()})
                    for side in sides:
                        for p in parts:
                            if p in times[side]:
                                timing.append(bench.record(dict(scene=name, width=size[0], height=size[1],
                                                                method=method, side=side, baseline=args.baseline,
                                                                part=p), "gpu_ms", "ms", times[side][p], better="lower"))
        print(f"\nGPU ms of {bench.repeats} rounds after {bench.warmup} warm-up rounds, one layer"
              + (", baseline and current alternately" if len(sides) > 1 else ""))
        if len(sides) > 1:
            bench.print_ab("side", "baseline", "current", records=timing, rows=("scene", "width", "height", "method",
                                                                                "part"))
        else:
            bench.print_table(timing, rows=("scene", "width", "height", "method"), columns="part")
    return 1 if wrong_total["current"] else 0


if __name__ == "__main__":
    raise SystemExit(main())
