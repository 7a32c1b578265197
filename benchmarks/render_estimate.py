"""What a render of many triangles costs, beside what Renderer.estimate says before it starts.

    python benchmarks/render_estimate.py [--device cpu] [--instances 2000] [--stacked 500]

The scenes: 2CylinderEngine's mesh 3 (2163 triangles) drawn by many glTF nodes
(ssrlab.lab.hostile_gltf.instanced, the fuzzer's instancing mutant) under the model's camera, with
ssrlab.scenes.load's default sun: "spread", --instances copies on a grid 60 units apart (most of
them small on screen or outside it), and "stacked", --stacked copies in one place (each covers
what the others do: the fill, not the triangles, is the work). Each configuration is rendered by
a fresh Renderer, once (the first render: scene upload, compilation, deep_gbuffer 'auto''s
measurement, the BVH) and once more (a repeat); wall seconds from the call to the colour read
back, at 640x360.

Columns: the drawn triangles, Renderer.estimate's geometry passes and seconds, the first render's
and the repeat's measured seconds, and the rates they imply: "draw rate", triangles x passes a
second of the first render (of a configuration without a BVH), and "bvh rate", triangles a second
into the BVH (the first render with fallback="bvh" less the same without it). ssrlab.workload.RATES
takes its figures from these columns on llvmpipe: the estimate leans long on the spread scenes and
short on the stacked ones, which it counts by their triangles only.
"""

from __future__ import annotations

import tempfile
import time
import warnings
from pathlib import Path

import ssrlab
from ssrlab.lab import hostile_gltf
from common import benchmark_arguments, open_renderer

CONFIGURATIONS = [
    ("1 layer", {}),
    ("1 layer, no shadow map", {"shadow_map_size": 0}),
    ("4 layers", {"layers": 4}),
    ("1 layer, fallback bvh", {"fallback": "bvh"}),
]


def measure(device: str, path: Path, settings: ssrlab.Settings) -> tuple[ssrlab.workload.Estimate, float, float]:
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
    args = ap.parse_args()
    renderer = open_renderer(args)
    device = renderer.info["device"]
    del renderer
    print(f"{args.width}x{args.height}; a fresh Renderer per configuration: its first render, then a repeat; wall "
          f"seconds. Estimates at ssrlab.workload.RATES[{device!r}] = "
          f"{ssrlab.workload.RATES.get(device, ssrlab.workload.RATES['cpu'])}\n")
    print(f"{'scene':<8} {'copies':>6} {'triangles':>11}  {'settings':<23} {'passes':>6} {'estimate s':>10} "
          f"{'first s':>8} {'repeat s':>8} {'draw rate':>10} {'bvh rate':>9}")
    with tempfile.TemporaryDirectory() as tmp:
        for layout, counts, spacing in (("spread", args.instances, 60.0), ("stacked", args.stacked, 0.0)):
            for n in counts:
                path = hostile_gltf.instanced(Path(tmp) / f"{layout}_{n}.glb", n, spacing=spacing)
                first_without_bvh = None
                for label, changes in CONFIGURATIONS:
                    settings = ssrlab.Settings(width=args.width, height=args.height, **changes)
                    est, first, repeat = measure(args.device, path, settings)
                    draw = bvh = "-"
                    if not est.bvh:
                        draw = f"{est.triangles * est.passes / first / 1e6:.2f}M"
                        if not changes:
                            first_without_bvh = first
                    elif first_without_bvh is not None and first > first_without_bvh:
                        bvh = f"{est.triangles / (first - first_without_bvh) / 1e6:.2f}M"
                    print(f"{layout:<8} {n:>6} {est.triangles:>11,}  {label:<23} {est.passes:>6} {est.seconds:>10.1f} "
                          f"{first:>8.2f} {repeat:>8.2f} {draw:>10} {bvh:>9}", flush=True)
    print("\ndraw rate: triangles x geometry passes / the first render's seconds; bvh rate: triangles / (the first "
          "render with fallback='bvh' less the first with the same settings without it)")


if __name__ == "__main__":
    main()
