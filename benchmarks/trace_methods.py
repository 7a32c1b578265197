"""Trace and resolve GPU time, and depth fetches per ray, for the linear and Hi-Z tracers.

    python benchmarks/trace_methods.py [--width 640 --height 360 --repeats 5]

For `spheres_and_boxes` and `hall`, with 1 and 4 G-buffer layers: linear tracing with stride
1, 2, 4 and 8, and Hi-Z tracing. Times are the median GPU time of the trace and resolve
passes (GL timestamp queries) over --repeats renders after 2 warm-up renders, all in one
run. Then seed 002's claim, that the hierarchical trace is far faster than linear marching
for long rays: the ratio of linear (stride 1) to Hi-Z depth fetches per ray, by the screen
distance the ray travelled to its hit, and the ratio of their trace times.
"""

from __future__ import annotations

import numpy as np

import ssrlab
from common import benchmark_arguments, median_timings, open_renderer
from ssrlab import experiments

CONFIGS = [("linear", 1), ("linear", 2), ("linear", 4), ("linear", 8), ("hiz", None)]


def settings(args, method, stride, layers, **kw):
    return ssrlab.Settings(width=args.width, height=args.height, layers=layers, method=method,
                           stride=float(stride or 1), **kw)


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=5)
    args = ap.parse_args()

    r = open_renderer(args)
    print(f"{args.width}x{args.height}, 1 ray per pixel, GGX sampling (default settings); median of "
          f"{args.repeats} runs after 2 warm-up runs; GPU milliseconds\n")
    print(f"{'scene':<18} {'layers':>6} {'method':<10} {'trace':>9} {'hiz_build':>9} {'resolve':>8} "
          f"{'fetches/ray':>11} {'hit rate':>8}")
    for name in args.scenes:
        scene = ssrlab.scenes.load(name)
        for layers in (1, 4):
            for method, stride in CONFIGS:
                s = settings(args, method, stride, layers)
                t = median_timings(r, scene, s, repeats=args.repeats)
                rays = r.render(scene, settings=s).rays
                traced = np.broadcast_to(rays.traced, rays.hit.shape) & (rays.weight > 0)
                label = f"linear/{stride}" if method == "linear" else "hiz"
                trace = t["trace_linear" if method == "linear" else "trace_hiz"]
                print(f"{name:<18} {layers:>6} {label:<10} {trace:>7.2f}ms {t.get('hiz_build', 0):>7.2f}ms "
                      f"{t['resolve']:>6.2f}ms {rays.mean_fetches():>11.1f} {rays.hit[traced].mean():>8.3f}")
        print()

    print("Seed 002's claim, long rays: linear (stride 1) over Hi-Z, same rays, one run")
    print(f"{'scene':<18} {'layers':>6} {'hit distance (px)':>18} {'rays':>7} {'linear fetches':>14} "
          f"{'hiz fetches':>11} {'ratio':>6}")
    for name in args.scenes:
        scene = ssrlab.scenes.load(name)
        for layers in (1, 4):
            bins = experiments.fetches_by_ray_length(r, scene, settings(args, "linear", 1, layers),
                                                     settings(args, "hiz", None, layers))
            for b in bins:
                if b["rays"] < 20:
                    continue
                rng = f"{b['lo']:g}-{b['hi']:g}" if b["hi"] < 1e9 else f">= {b['lo']:g}"
                fl, fh = b["fetches_a"], b["fetches_b"]
                print(f"{name:<18} {layers:>6} {rng:>18} {b['rays']:>7} {fl:>14.1f} {fh:>11.1f} {fl / fh:>5.1f}x")
            tl = median_timings(r, scene, settings(args, "linear", 1, layers), repeats=args.repeats)["trace_linear"]
            th = median_timings(r, scene, settings(args, "hiz", None, layers), repeats=args.repeats)
            hz = th["trace_hiz"] + th["hiz_build"]
            print(f"{name:<18} {layers:>6} {'trace time':>18} {'':>7} {tl:>12.2f}ms {hz:>9.2f}ms {tl / hz:>5.1f}x"
                  f"   (Hi-Z time includes hiz_build)")
        print()


if __name__ == "__main__":
    main()
