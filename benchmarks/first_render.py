"""Timings without compilation: the first render of a variant against the ones after it.

    python benchmarks/first_render.py [--width 160 --height 90 --repeats 9]

For each variant (linear and Hi-Z tracing, 1 and 4 layers, the thesis's and the pbr composite)
a fresh Renderer renders the same frame 1 + --repeats times. The first render compiles every
program and pays the driver's first-use costs, but untimed (Frame.warmup_runs = 1); its reported
GPU total should then match the later renders'. Printed: the first render's total, the median and
IQR of the later ones, their ratio, the first call's wall time (which does include compilation),
and a verdict only where the spread allows one.
"""

from __future__ import annotations

import statistics

import numpy as np

import ssrlab
from common import benchmark_arguments, device_header

VARIANTS = {
    "linear, 1 layer": dict(method="linear"),
    "hiz, 1 layer": dict(method="hiz"),
    "hiz, 4 layers, 4 rays": dict(method="hiz", layers=4, rays_per_pixel=4),
    "linear, pbr composite": dict(method="linear", composite="pbr"),
}


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=9)
    ap.set_defaults(width=160, height=90)
    args = ap.parse_args()
    print(device_header(ssrlab.Renderer(args.device)))
    print(f"{args.width}x{args.height}; each variant in a fresh renderer; GPU milliseconds (total of the passes)")
    print(f"\n{'scene':<18} {'variant':<24} {'first':>8} {'later median':>13} {'IQR':>7} {'first/later':>11}"
          f" {'first wall':>10}  verdict (within 20 %?)")
    for name in args.scenes:
        scene = ssrlab.scenes.load(name)
        for label, kw in VARIANTS.items():
            r = ssrlab.Renderer(args.device)
            s = ssrlab.Settings(width=args.width, height=args.height, **kw)
            first = r.render(scene, settings=s)
            later = [r.render(scene, settings=s).timings["total"] for _ in range(args.repeats)]
            med = statistics.median(later)
            q1, q3 = np.percentile(later, [25, 75])
            ratio = first.timings["total"] / med
            # One first render against the spread of the later ones: it shows a first-use cost
            # only if it lies above every later render and more than 20 % above their median.
            lo, hi = min(later), max(later)
            if abs(ratio - 1) <= 0.2:
                verdict = "yes"
            elif lo <= first.timings["total"] <= hi:
                verdict = f"within the later renders' range ({lo:.1f}-{hi:.1f} ms): noise, not a first-use cost"
            elif (q3 - q1) / med > 0.2:
                verdict = "too noisy to judge (IQR > 20 % of the median)"
            else:
                verdict = "no"
            print(f"{name:<18} {label:<24} {first.timings['total']:>8.2f} {med:>13.2f} {q3 - q1:>7.2f} "
                  f"{ratio:>10.2f}x {first.wall_ms:>8.0f}ms  {verdict}"
                  + ("" if first.warmup_runs == 1 else "  (first render was not warmed!)"))


if __name__ == "__main__":
    main()
