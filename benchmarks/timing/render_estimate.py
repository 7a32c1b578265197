"""What a render of many triangles costs, beside what Renderer.estimate says before it starts.

    python benchmarks/timing/render_estimate.py [--device cpu] [--instances 2000] [--stacked 500]

The scenes: 2CylinderEngine's mesh 3 (2163 triangles) drawn by many glTF nodes
(ssrlab.lab.hostile_gltf.instanced, the fuzzer's instancing mutant) under the model's camera, with
ssrlab.scenes.load's default sun: "spread", --instances copies on a grid 60 units apart (most of
them small on screen or outside it), and "stacked", --stacked copies in one place (each covers
what the others do: the fill, not the triangles, is the work). Each configuration is rendered by
a fresh Renderer, once (the first render: scene upload, compilation, deep_gbuffer 'auto''s
measurement, the BVH) and once more (a repeat); wall seconds from the call to the colour read
back, at 640x360; --rounds rounds of the protocol (no warm-up round: the first render is what is
measured), each a fresh Renderer. Every figure is a record; the table is rendered from them.

Columns: the drawn triangles, Renderer.estimate's geometry passes and seconds, the first render's
and the repeat's measured seconds, and the rates they imply: "draw rate", triangles x passes a
second of the first render (of a configuration without a BVH), and "bvh rate", triangles a second
into the BVH (the first render with fallback="bvh" less the same without it, round by round). ssrlab.workload.RATES
takes its figures from these columns on llvmpipe: the estimate leans long on the spread scenes and
short on the stacked ones, which it counts by their triangles only.
"""

from __future__ import annotations

import sys
import tempfile
import time
import warnings
from pathlib import Path

import ssrlab
from ssrlab.lab import hostile_gltf

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab import records  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402

CONFIGURATIONS = [
    ("1 layer", {}),
    ("1 layer, no shadow map", {"shadow_map_size": 0}),
    ("4 layers", {"layers": 4}),
    ("1 layer, fallback bvh", {"fallback": "bvh"}),
]


def measure(device: str, path: Path, settings: ssrlab.Settings):
    """One round: a fresh Renderer's estimate, its first render's and its repeat's wall seconds."""
    renderer = ssrlab.Renderer(device)
    scene = ssrlab.scenes.load(str(path))
    est = renderer.estimate(scene, settings)
    seconds = []
    with warnings.catch_warnings():
        # the long-work warning (measured here) and the model camera's far/near ratio (no image is scored)
        warnings.simplefilter("ignore", ssrlab.SceneWarning)
        warnings.simplefilter("ignore", ssrlab.renderer.DepthPrecisionWarning)
        for _ in range(2):
            start = time.perf_counter()
            renderer.render(scene, settings=settings).color
            seconds.append(time.perf_counter() - start)
    return est, seconds[0], seconds[1]


def main() -> None:
    ap = benchmark_arguments(__doc__)
    ap.add_argument("--instances", type=int, nargs="+", default=[2000], help="copies of the spread scenes")
    ap.add_argument("--stacked", type=int, nargs="+", default=[500], help="copies of the stacked scenes")
    ap.add_argument("--rounds", type=int, default=3, help="fresh renderers per configuration")
    args = ap.parse_args()
    renderer = open_renderer(args)
    device = renderer.info["device"]
    bench = Bench("render_estimate", args, renderer, repeats=args.rounds, warmup=0)
    del renderer
    print(f"{args.width}x{args.height}; {args.rounds} rounds, each a fresh Renderer per configuration: its first "
          f"render, then a repeat; wall seconds. Estimates at ssrlab.workload.RATES[{device!r}] = "
          f"{ssrlab.workload.RATES.get(device, ssrlab.workload.RATES['cpu'])}\n")
    with tempfile.TemporaryDirectory() as tmp:
        for layout, counts, spacing in (("spread", args.instances, 60.0), ("stacked", args.stacked, 0.0)):
            for n in counts:
                path = hostile_gltf.instanced(Path(tmp) / f"{layout}_{n}.glb", n, spacing=spacing)
                first_without_bvh = None
                for label, changes in CONFIGURATIONS:
                    settings = ssrlab.Settings(width=args.width, height=args.height, **changes)
                    last = {}

                    def run():
                        last["est"], first, repeat = measure(args.device, path, settings)
                        return {"first": first, "repeat": repeat}

                    t = bench.rounds({label: run})[label]
                    est = last["est"]
                    params = dict(scene=layout, copies=n, triangles=est.triangles, settings=label,
                                  width=args.width, height=args.height)
                    bench.record(params, "passes", "passes", [est.passes])
                    bench.record(params, "estimate", "estimated s", [est.seconds])  # a prediction, not a timing
                    bench.record(params, "first", "s", t["first"])
                    bench.record(params, "repeat", "s", t["repeat"])
                    rate = ""
                    if not est.bvh:
                        draw = bench.record(params, "draw_rate", "Mtri/s",
                                            [est.triangles * est.passes / v / 1e6 for v in t["first"]], better="higher")
                        rate = f", draw rate {records.cell(draw['samples'])} M"
                        if not changes:
                            first_without_bvh = t["first"]
                    elif first_without_bvh is not None:
                        # round by round: the same round's first render without the BVH
                        extra = [a - b for a, b in zip(t["first"], first_without_bvh)]
                        if all(x > 0 for x in extra):
                            bench.record(params, "bvh_rate", "Mtri/s", [est.triangles / x / 1e6 for x in extra],
                                         better="higher")
                    print(f"{layout} {n} copies, {label}: measured (estimate {est.seconds:.1f} s){rate}", flush=True)
    bench.print_table(rows=("scene", "copies", "triangles", "settings"),
                      order=["passes", "estimate", "first", "repeat", "draw_rate", "bvh_rate"])
    print("\ndraw rate: triangles x geometry passes / the first render's seconds; bvh rate: triangles / (the first "
          "render with fallback='bvh' less the first with the same settings without it, in the same round)")


if __name__ == "__main__":
    main()
