"""Timings without compilation: the first render of a variant against the ones after it.

    python benchmarks/timing/first_render.py [--width 160 --height 90 --rounds 3 --repeats 9]

For each variant (linear and Hi-Z tracing, 1 and 4 layers, the thesis's and the pbr composite)
each round opens a fresh Renderer and renders the same frame 1 + --repeats times (no warm-up
round: the first render is what is measured). The first render compiles every program and pays
the driver's first-use costs, but untimed (Frame.warmup_runs = 1); its reported GPU total should
then match the later renders'. Recorded per round: the first render's total, the later renders'
totals, the first over the median of the same round's later ones, and the first call's wall time
(which does include compilation). The table is rendered from the records; the verdict (is the
first render within 20 % of the later ones?) is goal_verdict's over the rounds' ratios: met, not
met, or undecided at this noise.
"""

from __future__ import annotations

import sys
from pathlib import Path
import statistics

import ssrlab

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab import records  # noqa: E402
from ssrlab.lab.protocol import Bench, goal_verdict  # noqa: E402

VARIANTS = {
    "linear, 1 layer": dict(method="linear"),
    "hiz, 1 layer": dict(method="hiz"),
    "hiz, 4 layers, 4 rays": dict(method="hiz", layers=4, rays_per_pixel=4),
    "linear, pbr composite": dict(method="linear", composite="pbr"),
}
WITHIN = 0.2  # the first render's total within this share of the later renders' median


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=9)
    ap.add_argument("--rounds", type=int, default=3, help="fresh renderers per variant (one first render each)")
    ap.set_defaults(width=160, height=90)
    args = ap.parse_args()
    bench = Bench("first_render", args, open_renderer(args), repeats=args.rounds, warmup=0)
    print(f"{args.width}x{args.height}; {args.rounds} rounds, each a fresh renderer per variant, its first render "
          f"and {args.repeats} later ones; GPU milliseconds (total of the passes)\n")
    rows = []
    for name in args.scenes:
        scene = ssrlab.scenes.load(name)
        for label, kw in VARIANTS.items():
            s = ssrlab.Settings(width=args.width, height=args.height, **kw)
            later_all, warmed = [], []

            def measure():
                r = ssrlab.Renderer(args.device)
                first = r.render(scene, settings=s)
                later = [r.render(scene, settings=s).timings["total"] for _ in range(args.repeats)]
                later_all.extend(later)
                warmed.append(first.warmup_runs == 1)
                return {"first": first.timings["total"], "first_wall": first.wall_ms,
                        "first_over_later": first.timings["total"] / statistics.median(later)}

            t = bench.rounds({label: measure})[label]
            params = dict(scene=name, variant=label, width=args.width, height=args.height)
            bench.record(params, "first", "ms", t["first"])
            bench.record(params, "later", "ms", later_all)
            ratio = bench.record(params, "first_over_later", "x", t["first_over_later"])
            bench.record(params, "first_wall", "ms", t["first_wall"])
            verdict = goal_verdict([abs(v - 1) for v in ratio["samples"]], "<=", WITHIN)
            rows.append([name, label, records.cell(ratio["samples"]),
                         verdict + ("" if all(warmed) else " (a first render was not warmed!)")])
    bench.print_table(rows=("scene", "variant"), order=["first", "later", "first_over_later", "first_wall"])
    print(f"\nfirst render within {100 * WITHIN:.0f} % of the later ones (|first / later - 1| <= {WITHIN:g} per round)")
    print(records.markdown(["scene", "variant", "first / later", "verdict"], rows))


if __name__ == "__main__":
    main()
