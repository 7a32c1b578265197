"""Where a frame's time goes: every timing of the chain, sub-passes included, and the CPU side.

    python benchmarks/timing/frame_breakdown.py [--width 1920 --height 1080] [--device gpu] [--repeats 7]

One layer of Hi-Z mirror rays (1 ray, reuse radius 1: the trace + resolve pair) at the
default settings, then one setting changed at a time: the deep G-buffer by peeling and by
visibility (the default 'auto' measures and picks), skip on, reuse radius 0, Hi-Z start level 0,
max_steps 64 (how much of the trace is a tail of long walks), 4 layers, 8 layers by peeling and
by visibility lists, and the thesis's
configuration. Per case: the median GPU ms of every timing key (e.g. `classify.clear`,
`depth_peel.layer0`, which the roofline leaves out) over `repeats` renders after a warm-up, the
render() wall time, the time to read `frame.color` back, and the trace's depth fetches per ray
(from `rays.sample`, so with skip on or off). Every figure is a record (ssrlab.lab.records) with
its samples; the last table is rendered from them.
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402

BASE = dict(layers=1, method="hiz", sampling="mirror", rays_per_pixel=1, reuse_radius=1)
CASES = {
    "hiz_mirror": {},
    # the deep G-buffer's exact constructions named (the default 'auto' picks one by measurement)
    "peel": dict(deep_gbuffer="peel"),
    "visibility": dict(deep_gbuffer="visibility"),
    "skip_on": dict(skip=True),
    "reuse0": dict(reuse_radius=0),
    "start_level0": dict(hiz_start_level=0),
    "max_steps64": dict(max_steps=64),
    "layers4": dict(layers=4),
    "layers8_peel": dict(layers=8, deep_gbuffer="peel"),
    "layers8_visibility_lists": dict(layers=8, deep_gbuffer="visibility_lists"),
    "thesis": dict(layers=4, rays_per_pixel=4, stride=4.0, downscale=2, max_steps=250, method="linear",
                   sampling="vndf"),
}


def main(argv=None) -> int:
    ap = benchmark_arguments(__doc__, repeats=7, settings=True)
    ap.set_defaults(scenes=["hall", "spheres_and_boxes"])
    args = ap.parse_args(argv)
    import ssrlab

    r = open_renderer(args)
    bench = Bench("frame_breakdown", args, r, warmup=1)
    print(f"{args.width}x{args.height}; GPU ms, medians of {args.repeats} renders after a warm-up")
    for scene_name in args.scenes:
        scene = ssrlab.scenes.load(scene_name)
        for name, kw in CASES.items():
            s = ssrlab.Settings(width=args.width, height=args.height, **{**BASE, **kw, **bench.settings})
            last = {}

            def measure():
                t0 = time.perf_counter()
                f = r.render(scene, settings=s)
                t1 = time.perf_counter()
                f.color
                t2 = time.perf_counter()
                last["frame"] = f
                return {**f.timings, "render_wall": (t1 - t0) * 1e3, "color_read": (t2 - t1) * 1e3}

            values = bench.rounds({name: measure})[name]
            f = last["frame"]
            sample = f.read("rays.sample")
            rays = int((sample[..., 0] > 0).sum())
            fetches = float(sample[..., 2].astype(np.float64).sum())
            params = dict(scene=scene_name, case=name, width=args.width, height=args.height,
                          skip=f.settings.skip, deep_gbuffer=f.settings.deep_gbuffer)
            timings = [k for k in values if k not in ("render_wall", "color_read")]
            bench.record_all(params, values, "ms", timings)
            bench.record({**params, "side": "cpu"}, "render_wall", "ms", values["render_wall"])
            bench.record({**params, "side": "cpu"}, "color_read", "ms", values["color_read"])
            bench.record(params, "rays", "count", [rays])
            bench.record(params, "depth_fetches_per_ray", "fetches", [fetches / max(rays, 1)])
            med = {k: statistics.median(values[k]) for k in timings}
            print(f"{scene_name} {name} (skip={f.settings.skip}, "
                  f"deep_gbuffer={f.settings.deep_gbuffer}): "
                  + ", ".join(f"{k} {v:.3f}" for k, v in med.items()))
            print(f"   render() wall {statistics.median(values['render_wall']):.2f} ms, color read "
                  f"{statistics.median(values['color_read']):.2f} ms, "
                  f"{rays} rays, {fetches / max(rays, 1):.1f} depth fetches per ray", flush=True)
            last.clear()
    print("\nthe frame and its main passes, GPU ms (from the records)")
    main_passes = [k for k in ("total", "depth_peel", "deep_gbuffer", "lighting", "hiz_build", "trace_hiz",
                               "trace_linear", "resolve") if bench.find(k)]
    bench.print_table([x for x in bench.recorder.records if x["metric"] in main_passes and "side" not in x["params"]],
                      rows=("scene", "case"), columns="metric", order=main_passes)
    return 0


if __name__ == "__main__":
    sys.exit(main())
