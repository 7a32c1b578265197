"""What each shadow-casting light costs: the shadow_map pass's GPU time (and the lighting pass's,
which reads every map) against the casting lights.

    python benchmarks/timing/shadows.py [--width 320 --height 180] [--scenes hall] [--repeats 9]

Cases, on each scene's own sun (a directional caster): "1 directional"; "+ spot" adds a casting
spot light (a second layer of the 2D array); "+ point" adds a casting point light too (a cube:
six faces, six draws of the scene). The cases run interleaved round by round after the
protocol's warm-up rounds (ssrlab.lab.protocol: compilation and the scene upload are not timed);
every figure is a record with its samples, and the table is rendered from them (median
[interquartile range]); shadow_map_ratio is each round's shadow_map over the same round's one
directional caster. The renderer keeps a scene's maps between frames; interleaved,
each render follows another scene's and draws its maps (checked), which is what is timed. Settings.shadow_map_size is the default unless --map-size.
Memory: shadow_map_size^2 x 4 bytes x (layers + 6 x cubes).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402


def cases(scene_name: str):
    """(name, scene, layers, cubes) with 1, 2 and 3 casting lights."""
    import ssrlab

    base = ssrlab.scenes.load(scene_name)
    lo, hi = (np.asarray(v, np.float64) for v in base.bounds)
    centre, size = (lo + hi) / 2, hi - lo
    top = lo[1] + 0.8 * size[1]
    spot = ssrlab.spot_light((centre[0] + 0.2 * size[0], top, centre[2]), (-0.3, -1.0, -0.2),
                             inner_cone=0.4, outer_cone=0.7, intensity=20.0, cast_shadow=True)
    point = ssrlab.point_light((centre[0] - 0.2 * size[0], lo[1] + 0.4 * size[1], centre[2]), intensity=8.0,
                               cast_shadow=True)
    out = []
    for name, extra, layers, cubes in [("1 directional", [], 1, 0), ("+ spot", [spot], 2, 0),
                                       ("+ point", [spot, point], 2, 1)]:
        s = ssrlab.scenes.load(scene_name)
        for light in extra:
            s.add_light(light)
        out.append((name, s, layers, cubes))
    return out


def main(argv=None) -> int:
    ap = benchmark_arguments(__doc__, repeats=9)
    ap.set_defaults(width=320, height=180, scenes=["hall"])
    ap.add_argument("--map-size", type=int, default=None, help="Settings.shadow_map_size (default: the setting's)")
    args = ap.parse_args(argv)
    import ssrlab
    from ssrlab.lab.protocol import Bench

    r = open_renderer(args)
    bench = Bench("shadows", args, r)
    kw = {} if args.map_size is None else dict(shadow_map_size=args.map_size)
    settings = ssrlab.Settings(width=args.width, height=args.height, **kw)
    n = settings.shadow_map_size
    print(f"{args.width}x{args.height}, shadow_map_size {n}; GPU ms of {args.repeats} interleaved rounds after "
          f"{bench.warmup} warm-up rounds")
    for scene_name in args.scenes:
        runs = cases(scene_name)

        def measure(scene, layers, cubes):
            def run():
                f = r.render(scene, settings=settings)
                # Each render follows another scene's: its maps are drawn, not reused from the last frame.
                assert f.stats["shadow_maps_rendered"] == layers + cubes, f.stats
                return {k: f.timings[k] for k in ("shadow_map", "lighting")}
            return run

        times = bench.rounds({name: measure(scene, layers, cubes) for name, scene, layers, cubes in runs})
        base = times[runs[0][0]]["shadow_map"]
        for name, _, layers, cubes in runs:
            params = dict(scene=scene_name, case=name, map_layers=layers, cubes=cubes, map_size=n,
                          width=args.width, height=args.height)
            bench.record_all(params, times[name], "ms", ("shadow_map", "lighting"))
            bench.record(params, "shadow_map_ratio", "x", [a / b for a, b in zip(times[name]["shadow_map"], base)])
            bench.record(params, "map_memory", "MiB", [n * n * 4 * (layers + 6 * cubes) / 2**20])
    bench.print_table(rows=("scene", "case", "map_layers", "cubes"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
