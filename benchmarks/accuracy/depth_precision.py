"""Depth precision against the near/far ratio, standard and reversed-Z depth (
seed 000 2.3.4, seed 002 4.6.3): view-depth reconstruction error against the exact depth
(Embree) and SSR hit-position error against the per-ray reference, per distance, for
far/near = 1e2 ... 1e8 (ssrlab.precision). Every figure is a record (one value: the measurement
is deterministic); prints the table rendered from them and, per mode, the largest ratio keeping
the hit-position error under one pixel (the README's table).

    python benchmarks/accuracy/depth_precision.py                     # 320x180, linear tracer
    python benchmarks/accuracy/depth_precision.py --method hiz --width 160 --height 90
"""

from __future__ import annotations

import sys
from pathlib import Path
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402


def main() -> None:
    ap = benchmark_arguments(__doc__)
    ap.set_defaults(width=320, height=180)
    ap.add_argument("--method", default="linear", choices=("linear", "hiz"))
    ap.add_argument("--bins", action="store_true", help="also print every distance bin")
    args = ap.parse_args()
    import ssrlab.precision as P
    from ssrlab.renderer import STANDARD_DEPTH_SAFE_RATIO

    from ssrlab.lab.protocol import Bench

    renderer = open_renderer(args)
    bench = Bench("depth_precision", args, renderer)
    rows = P.study(renderer, width=args.width, height=args.height, method=args.method)
    for r in rows:
        params = dict(mode=r["mode"], far_over_near=f"{r['ratio']:.0e}", near=f"{r['near']:.0e}",
                      width=args.width, height=args.height, method=args.method)
        for key, unit in (("depth_rel_median", "relative"), ("depth_rel_p99", "relative"), ("hit_px_median", "px"),
                          ("hit_px_p95", "px")):
            bench.record(params, key, unit, [r[key]])
        bench.record(params, "worst_bin_hit_px_p95", "px", [P.worst_bin_p95(r)])
        bench.record(params, "false_hits", "share", [r["false_hits"]])
        bench.record(params, "true_hits_found", "share", [r["found"]], better="higher")
    print(f"scene: mirror floor, boxes at {', '.join(f'{d:g}' for d in P.BOX_DISTANCES)}, wall at "
          f"{P.WALL_DISTANCE:g}; far = {P.FAR:g}, near = far / ratio; {args.width}x{args.height}, "
          f"{args.method} tracer, mirror rays; pixels nearer than {P.DISTANCE_BINS[0]:g} not scored")
    bench.print_table(rows=("mode", "far_over_near", "near"), digits=3, note=False)
    if args.bins:
        for r in rows:
            print(r["mode"], f"{r['ratio']:.0e}", " ".join(
                f"[{b['lo']:g},{b['hi']:g}): depth {b['depth_rel_p99']:.1e}, p95 {b['hit_px_p95']:.2f} px "
                f"({b['rays']} rays)" for b in r["bins"]))
    for mode in P.MODES:
        best = P.largest_safe_ratio(rows, mode)
        measured = max(r["ratio"] for r in rows if r["mode"] == mode)
        text = "none" if best is None else f"{best:.0e}" + (" (the largest measured)" if best == measured else "")
        print(f"{mode}: hit-position error under 1 px (every distance bin's p95) up to far/near = {text}")
    print(f"Renderer.render warns above far/near = {STANDARD_DEPTH_SAFE_RATIO:.0e} in depth_mode='standard'")


if __name__ == "__main__":
    main()
