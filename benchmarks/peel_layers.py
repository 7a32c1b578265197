"""Geometry + depth-peeling GPU time against the number of G-buffer layers.

    python benchmarks/peel_layers.py [--width 640 --height 360 --repeats 7]

For `spheres_and_boxes` and `hall`, renders with 1, 2, 4 and 8 layers and prints the median
GPU time of the depth_peel pass (every layer's geometry pass), per layer, and relative to one
layer. The thesis (seed 000, 3.2.1) finds time growing linearly in layers: a peel re-renders
all geometry, and the discard in its fragment shader defeats early depth testing.
"""

from __future__ import annotations

import numpy as np

import ssrlab
from common import benchmark_arguments, median_timings, open_renderer


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=7)
    ap.add_argument("--layers", type=int, nargs="+", default=[1, 2, 4, 8])
    args = ap.parse_args()

    renderer = open_renderer(args)
    print(f"{args.width}x{args.height}, median of {args.repeats} runs after 2 warm-up runs; GPU milliseconds\n")
    print(f"{'scene':<18} {'triangles':>9} {'layers':>6} {'depth_peel':>11} {'per layer':>10} {'vs 1 layer':>10}"
          f" {'layer 0':>8} {'layers 1+ (mean)':>16}")
    for name in args.scenes:
        scene = ssrlab.scenes.load(name)
        rows = []
        for layers in args.layers:
            s = ssrlab.Settings(width=args.width, height=args.height, layers=layers, deep_gbuffer="peel")
            t = median_timings(renderer, scene, s, repeats=args.repeats)
            rows.append((layers, t))
        base = rows[0][1]["depth_peel"]
        for layers, t in rows:
            rest = [t[f"depth_peel.layer{i}"] for i in range(1, layers)]
            print(f"{name:<18} {scene.triangle_count:>9} {layers:>6} {t['depth_peel']:>9.2f}ms "
                  f"{t['depth_peel'] / layers:>8.2f}ms {t['depth_peel'] / base:>9.2f}x "
                  f"{t['depth_peel.layer0']:>6.2f}ms {np.mean(rest) if rest else float('nan'):>14.2f}ms")
        xs = np.array([l for l, _ in rows], dtype=float)
        ys = np.array([t["depth_peel"] for _, t in rows])
        slope, intercept = np.polyfit(xs, ys, 1)
        r2 = 1 - np.sum((ys - (slope * xs + intercept)) ** 2) / np.sum((ys - ys.mean()) ** 2)
        print(f"{'':<18} linear fit: {slope:.2f} ms per layer + {intercept:.2f} ms, R^2 = {r2:.3f}\n")


if __name__ == "__main__":
    main()
