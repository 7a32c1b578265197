"""What an emissive texture costs a frame: ssrlab.crosscheck's emissive-texture scene (a black quad
emitting a checkerboard over a mirror floor) rendered with its emissive texture and with the
factor alone, interleaved, `--repeats` timed frames each (first use excluded). Prints the median,
min-max and interquartile range of depth_peel (which writes gbuffer.emission only with the
texture), lighting (which reads it) and the frame's total, the paired ratio texture / factor and
a verdict that says 'undecided' where the two ranges overlap.

    python benchmarks/emissive_texture.py                       # 640x360, 4 layers
    python benchmarks/emissive_texture.py --deep-gbuffer lists
"""

from __future__ import annotations

import numpy as np

from common import benchmark_arguments, open_renderer

import ssrlab
from ssrlab import crosscheck as cc
from ssrlab.lab.timing import median_range, paired, verdict

PARTS = ("depth_peel", "lighting", "total")


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=9)
    ap.add_argument("--layers", type=int, default=4)
    ap.add_argument("--deep-gbuffer", default="peel", choices=("peel", "lists"))
    args = ap.parse_args()
    renderer = open_renderer(args)
    textured = cc.emissive_texture_crosscheck_scene()
    factor = cc.emissive_texture_crosscheck_scene()
    quad = factor.object_count - 1
    m = factor.material(quad)
    m.emissive_texture = -1
    factor.set_material(quad, m)
    settings = ssrlab.Settings(width=args.width, height=args.height, layers=args.layers,
                               deep_gbuffer=args.deep_gbuffer)
    for s in (textured, factor):
        renderer.render(s, settings=settings)  # first use: compilation, uploads
    times = {"texture": {p: [] for p in PARTS}, "factor": {p: [] for p in PARTS}}
    for _ in range(args.repeats):
        for name, s in (("texture", textured), ("factor", factor)):
            t = renderer.render(s, settings=settings).timings
            for p in PARTS:
                times[name][p].append(t[p])
    print(f"{args.width}x{args.height}, {args.layers} layers, deep_gbuffer={args.deep_gbuffer}, "
          f"{args.repeats} interleaved repeats; ms (median [min, max], IQR)")
    for p in PARTS:
        a, b = times["texture"][p], times["factor"][p]
        ratio = paired(a, b)
        iqr = lambda v: float(np.subtract(*np.percentile(v, [75, 25])))  # noqa: E731
        ma, mb = median_range(a), median_range(b)
        print(f"{p:11s} texture {ma[0]:8.2f} [{ma[1]:.2f}, {ma[2]:.2f}] IQR {iqr(a):.2f} | factor {mb[0]:8.2f} "
              f"[{mb[1]:.2f}, {mb[2]:.2f}] IQR {iqr(b):.2f} | texture/factor {np.median(ratio):.3f} "
              f"-> texture {verdict(mb, ma)}")


if __name__ == "__main__":
    main()
