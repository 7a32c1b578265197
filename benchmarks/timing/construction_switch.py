"""What one layer of the deep G-buffer costs, by peeling and by visibility, depending on the
renders around it: its own configuration rendered alone, or alternating with 8 peeled layers or
with the other construction, each frame released at once or kept.

    python benchmarks/timing/construction_switch.py [--width 1920 --height 1080] [--device gpu] [--repeats 9]

A renderer keeps a pool of released frames' texture sets and reuses them; a kept frame, or a render
after another configuration, takes textures the GPU has not touched before, and their first use
lands in the G-buffer's timers. benchmarks/timing/deep_gbuffer.py interleaves its configurations round by
round (fair against drift), so on a GPU its one-peeled-layer figure carries this cost; a script
rendering one configuration and releasing its frames does not. Per line: the median GPU ms of
`deep_gbuffer` (the whole construction) and of its first part (`depth_peel.setup` for peeling, the
raster `visibility_buffer` for visibility) over `repeats` rounds after one untimed round (the
protocol's rounds, ssrlab.lab.protocol), recorded with their samples; the table is rendered from
the records.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402

PARTS = {"peel": "depth_peel.setup", "visibility": "visibility_buffer"}


def pattern_round(renderer, scene, pattern, keep: bool, kept: list):
    """One round: every configuration of `pattern` rendered in turn; the first one's timings."""
    def measure():
        out = {}
        for k, s in enumerate(pattern):
            f = renderer.render(scene, settings=s)
            if k == 0:
                out = {"deep_gbuffer": f.timings["deep_gbuffer"], "part": f.timings[PARTS[s.deep_gbuffer]]}
            if keep:
                kept.append(f)
            else:
                f.release()
        return out
    return measure


def main(argv=None) -> int:
    ap = benchmark_arguments(__doc__, repeats=9)
    ap.set_defaults(scenes=["hall"])
    args = ap.parse_args(argv)
    import ssrlab
    from ssrlab.lab.protocol import Bench

    r = open_renderer(args)
    bench = Bench("construction_switch", args, r, warmup=1)
    base = ssrlab.Settings(width=args.width, height=args.height, layers=1, method="off", shadow_map_size=0)
    one = {m: base.replace(deep_gbuffer=m) for m in PARTS}
    eight = base.replace(layers=8, deep_gbuffer="peel")
    print(f"{args.width}x{args.height}, one layer; GPU ms of {args.repeats} rounds after one untimed round")
    for name in args.scenes:
        scene = ssrlab.scenes.load(name)
        for m, other in (("peel", "visibility"), ("visibility", "peel")):
            for label, pattern in ((f"{m} alone", [one[m]]), (f"{m} after 8 peeled layers", [one[m], eight]),
                                   (f"{m} after {other}", [one[m], one[other]])):
                for keep in (False, True):
                    kept = []
                    t = bench.rounds({label: pattern_round(r, scene, pattern, keep, kept)})[label]
                    kept.clear()
                    params = dict(scene=name, construction=m, renders=label,
                                  frames="kept" if keep else "released", width=args.width, height=args.height)
                    bench.record(params, "deep_gbuffer", "ms", t["deep_gbuffer"])
                    bench.record({**params}, "first_part", "ms", t["part"], part=PARTS[m])
    bench.print_table(rows=("scene", "renders", "frames"), order=["deep_gbuffer", "first_part"])
    print("first_part: " + ", ".join(f"{k}: {v}" for k, v in PARTS.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
