"""Trace and resolve GPU time, and depth fetches per ray, for the linear and Hi-Z tracers.

    python benchmarks/timing/trace_methods.py [--width 640 --height 360 --repeats 5]

For `spheres_and_boxes` and `hall`, with 1 and 4 G-buffer layers: linear tracing with stride
1, 2, 4 and 8, and Hi-Z tracing. Times are the median GPU time of the trace and resolve
passes (GL timestamp queries) over --repeats rounds after 2 warm-up rounds, the configurations of a
scene and layer count interleaved round by round (ssrlab.lab.protocol); every figure is a record
and the tables are rendered from them. Then seed 002's claim, that the hierarchical trace is far faster than linear marching
for long rays: the ratio of linear (stride 1) to Hi-Z depth fetches per ray, by the screen
distance the ray travelled to its hit, and the ratio of their trace times.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import ssrlab

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402
from ssrlab import experiments  # noqa: E402
from ssrlab.lab import records  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402

CONFIGS = [("linear", 1), ("linear", 2), ("linear", 4), ("linear", 8), ("hiz", None)]


def settings(args, method, stride, layers, **kw):
    return ssrlab.Settings(width=args.width, height=args.height, layers=layers, method=method,
                           stride=float(stride or 1), **kw)


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=5, settings=True)
    args = ap.parse_args()

    r = open_renderer(args)
    bench = Bench("trace_methods", args, r)
    print(f"{args.width}x{args.height}, 1 ray per pixel, GGX sampling (default settings); median [25th-75th "
          f"percentile] of {args.repeats} rounds after 2 warm-up rounds, the configurations interleaved round by "
          f"round; GPU milliseconds\n")
    for name in args.scenes:
        scene = ssrlab.scenes.load(name)
        for layers in (1, 4):
            configs = {(f"linear/{stride}" if method == "linear" else "hiz"):
                       settings(args, method, stride, layers, **bench.settings) for method, stride in CONFIGS}
            times = bench.frames(r, scene, configs)
            for label, s in configs.items():
                params = dict(scene=name, layers=layers, method=label, width=args.width, height=args.height)
                trace = "trace_linear" if s.method == "linear" else "trace_hiz"
                t = times[label]
                bench.record(params, "trace", "ms", t[trace])
                if "hiz_build" in t:
                    bench.record(params, "hiz_build", "ms", t["hiz_build"])
                bench.record_all(params, t, "ms", ("resolve", "total"))
                rays = r.render(scene, settings=s).rays
                traced = np.broadcast_to(rays.traced, rays.hit.shape) & (rays.weight > 0)
                bench.record(params, "fetches_per_ray", "fetches", [rays.mean_fetches()])
                bench.record(params, "hit_rate", "share", [float(rays.hit[traced].mean())], better="higher")
    bench.print_table(rows=("scene", "layers", "method"),
                      order=["trace", "hiz_build", "resolve", "total", "fetches_per_ray", "hit_rate"])

    print("\nSeed 002's claim, long rays: linear (stride 1) over Hi-Z, same rays, one run")
    rows = []
    for name in args.scenes:
        scene = ssrlab.scenes.load(name)
        for layers in (1, 4):
            bins = experiments.fetches_by_ray_length(r, scene, settings(args, "linear", 1, layers, **bench.settings),
                                                     settings(args, "hiz", None, layers, **bench.settings))
            for b in bins:
                if b["rays"] < 20:
                    continue
                rng = f"{b['lo']:g}-{b['hi']:g}" if b["hi"] < 1e9 else f">= {b['lo']:g}"
                params = dict(scene=name, layers=layers, hit_distance_px=rng, width=args.width, height=args.height)
                fl = bench.record({**params, "method": "linear/1"}, "fetches_per_ray", "fetches", [b["fetches_a"]])
                fh = bench.record({**params, "method": "hiz"}, "fetches_per_ray", "fetches", [b["fetches_b"]])
                a, c = fl["samples"][0], fh["samples"][0]
                rows.append([name, layers, rng, b["rays"], f"{a:.1f}", f"{c:.1f}", f"{a / c:.1f}x"])
            tl = bench.find("trace", scene=name, layers=layers, method="linear/1")[0]["samples"]
            hz = bench.find("trace", scene=name, layers=layers, method="hiz")[0]["samples"]
            hb = bench.find("hiz_build", scene=name, layers=layers, method="hiz")[0]["samples"]
            # one ratio per round: both sides were rendered in the same round
            ratio = [a / (b + c) for a, b, c in zip(tl, hz, hb)]
            rows.append([name, layers, "trace time (Hi-Z with hiz_build)", "", records.cell(tl) + " ms",
                         records.cell([b + c for b, c in zip(hz, hb)]) + " ms", records.cell(ratio) + "x"])
    print(records.markdown(["scene", "layers", "hit distance (px)", "rays", "linear fetches", "hiz fetches",
                            "ratio"], rows))


if __name__ == "__main__":
    main()
