"""One pass of two shader trees, frames interleaved in one process, and how a SIMD vector's lanes
use the walk steps it pays for.

    python benchmarks/tools/ab_pass.py BEFORE_DIR [AFTER_DIR] [--pass trace_hiz] [--repeats 9]
                                 [--set key=value ...] [--lane-use]

BEFORE_DIR, AFTER_DIR: shader folders (AFTER_DIR defaults to the installed package's shaders), e.g.
`git archive <commit> shaders | tar -x -C /tmp/before` or a copy of shaders/ with one change. Both
renderers draw the same frames in turn (2 warm-ups each; timings never include compilation); the
script prints the pass's median GPU ms (min-max) before and after, their ratio, the trace's depth
fetches and share of the dependent-fetch rate (the roofline's kernel at the frame's size, run between
the frames), and the largest difference between the two renderers' hit positions. The default
settings are the roofline's 1-layer Hi-Z mirror frame; --set overrides any of them.

--lane-use: from the per-ray step counts (`frame.rays.steps`, a full-screen trace), the share of the
steps an 8-lane vector pays for that its lanes use (it runs until its longest walk ends), for the
trace's two lane layouts over classify's list order (32x32 regions, 4x4 blocks): two rays per lane
with a vector on entries i and i + 32 of a 64-entry group, and on 16 consecutive entries.
"""

from __future__ import annotations

import statistics
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402

from ssrlab.lab.lanes import lane_use  # noqa: E402
from ssrlab.lab.protocol import parse_set  # noqa: E402

HIZ_MIRROR = dict(layers=1, method="hiz", sampling="mirror", rays_per_pixel=1, reuse_radius=1)


def main(argv=None) -> int:
    ap = benchmark_arguments(__doc__, repeats=9)
    ap.add_argument("before", help="shader folder before the change")
    ap.add_argument("after", nargs="?", help="shader folder after it (default: the installed shaders)")
    ap.add_argument("--pass", dest="pass_name", default="trace_hiz", help="timing key to compare")
    ap.add_argument("--set", nargs="*", default=[], metavar="KEY=VALUE", help="settings overrides")
    ap.add_argument("--lane-use", action="store_true")
    args = ap.parse_args(argv)

    import ssrlab

    now = open_renderer(args)
    after = ssrlab.Renderer(args.device, shader_dir=args.after) if args.after else now
    before = ssrlab.Renderer(args.device, shader_dir=args.before)
    kw = dict(HIZ_MIRROR)
    try:
        kw.update(parse_set(args.set))
    except ValueError as e:
        ap.error(str(e))
    print(f"{args.width}x{args.height}, {', '.join(f'{k}={v}' for k, v in kw.items())}; "
          f"medians (min-max) of {args.repeats}, frames interleaved")
    for scene_name in args.scenes:
        scene = getattr(ssrlab.scenes, scene_name)()
        s = ssrlab.Settings(width=args.width, height=args.height, **kw)
        for r in (before, after):
            for _ in range(2):
                r.render(scene, settings=s)
        tb, ta, dep = [], [], []
        for _ in range(args.repeats):
            fb, fa = before.render(scene, settings=s), after.render(scene, settings=s)
            tb.append(fb.timings[args.pass_name])
            ta.append(fa.timings[args.pass_name])
            dep += after.microbenchmark("dependent", args.width, args.height, 64, 1)
        mb, ma = statistics.median(tb), statistics.median(ta)
        line = (f"{scene_name} {args.pass_name}: before {mb:.2f} ms ({min(tb):.2f}-{max(tb):.2f}), "
                f"after {ma:.2f} ms ({min(ta):.2f}-{max(ta):.2f}), after / before {ma / mb:.3f}")
        if "depth_fetches" in fa.stats and args.pass_name.startswith("trace"):
            rate = args.width * args.height * 64 / (statistics.median(dep) * 1e-3)
            line += (f"; depth fetches {fb.stats['depth_fetches']:,} / {fa.stats['depth_fetches']:,}, share of the "
                     f"dependent-fetch rate {fb.stats['depth_fetches'] / (mb * 1e-3) / rate:.3f} / "
                     f"{fa.stats['depth_fetches'] / (ma * 1e-3) / rate:.3f}")
        hb, ha = np.nan_to_num(fb.rays.hit_pixel), np.nan_to_num(fa.rays.hit_pixel)
        line += f"; largest hit difference {float(np.abs(hb - ha).max()):.2e} px"
        print(line)
        if args.lane_use:
            full = ssrlab.Settings(width=args.width, height=args.height, **{**kw, "skip": False})
            steps = np.asarray(after.render(scene, settings=full).rays.steps, dtype=np.float64)
            steps = steps[0] if steps.ndim == 3 else steps  # the first ray's (rays, H, W)
            use = lane_use(steps)
            print(f"  lane use (steps used / paid, 2 rays per lane): "
                  + ", ".join(f"{k} {v:.3f}" for k, v in use.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
