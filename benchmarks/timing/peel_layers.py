"""Geometry + depth-peeling GPU time against the number of G-buffer layers.

    python benchmarks/timing/peel_layers.py [--width 640 --height 360 --repeats 7]

For `spheres_and_boxes` and `hall`, renders with 1, 2, 4 and 8 layers (peeled), the layer counts
interleaved round by round after the protocol's warm-up rounds (ssrlab.lab.protocol), and records
the GPU time of the depth_peel pass (every layer's geometry pass), per layer, of layer 0 and the
mean of the later layers, and each round's ratio to the same round's one layer. The table is
rendered from the records. The thesis (seed 000, 3.2.1) finds time growing linearly in layers:
a peel re-renders all geometry, and the discard in its fragment shader defeats early depth
testing; the linear fit of the medians is printed with its R^2.
"""

from __future__ import annotations

import sys
from pathlib import Path
import statistics

import numpy as np

import ssrlab

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=7)
    ap.add_argument("--layers", type=int, nargs="+", default=[1, 2, 4, 8])
    args = ap.parse_args()

    renderer = open_renderer(args)
    bench = Bench("peel_layers", args, renderer)
    print(f"{args.width}x{args.height}, {args.repeats} rounds after {bench.warmup} warm-up rounds, the layer counts "
          f"interleaved; GPU milliseconds\n")
    for name in args.scenes:
        scene = ssrlab.scenes.load(name)
        configs = {layers: ssrlab.Settings(width=args.width, height=args.height, layers=layers, deep_gbuffer="peel")
                   for layers in args.layers}
        times = bench.frames(renderer, scene, configs)
        base = times[args.layers[0]]["depth_peel"]
        for layers, t in times.items():
            params = dict(scene=name, triangles=scene.triangle_count, layers=layers, width=args.width,
                          height=args.height)
            peel = t["depth_peel"]
            bench.record(params, "depth_peel", "ms", peel)
            bench.record(params, "per_layer", "ms", [v / layers for v in peel])
            bench.record(params, f"vs_{args.layers[0]}_layer", "x", [a / b for a, b in zip(peel, base)])
            bench.record(params, "layer0", "ms", t["depth_peel.layer0"])
            if layers > 1:
                rest = np.mean([t[f"depth_peel.layer{i}"] for i in range(1, layers)], axis=0)
                bench.record(params, "later_layers_mean", "ms", rest)
        xs = np.array(args.layers, float)
        ys = np.array([statistics.median(bench.find("depth_peel", scene=name, layers=n)[0]["samples"])
                       for n in args.layers])
        if len(xs) > 1:
            slope, intercept = np.polyfit(xs, ys, 1)
            r2 = 1 - np.sum((ys - (slope * xs + intercept)) ** 2) / max(np.sum((ys - ys.mean()) ** 2), 1e-300)
            print(f"{name}: linear fit of the medians: {slope:.2f} ms per layer + {intercept:.2f} ms, R^2 = {r2:.3f}")
    print()
    bench.print_table(rows=("scene", "triangles", "layers"))


if __name__ == "__main__":
    main()
