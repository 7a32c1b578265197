"""Where a frame's time goes: every timing of the chain, sub-passes included, and the CPU side.

    python benchmarks/frame_breakdown.py [--width 1920 --height 1080] [--device gpu] [--repeats 7]

One layer of Hi-Z mirror rays (1 ray, reuse radius 1: the trace + resolve pair) at the
default settings, then one setting changed at a time: the deep G-buffer by peeling and by
visibility (the default 'auto' measures and picks), skip on, reuse radius 0, Hi-Z start level 0,
max_steps 64 (how much of the trace is a tail of long walks), 4 layers, 8 layers by peeling and
by visibility lists, and the thesis's
configuration. Per case: the median GPU ms of every timing key (e.g. `classify.clear`,
`depth_peel.layer0`, which the roofline leaves out) over `repeats` renders after a warm-up, the
render() wall time, the time to read `frame.color` back, and the trace's depth fetches per ray
(from `rays.sample`, so with skip on or off).
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import benchmark_arguments, open_renderer  # noqa: E402

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
    ap = benchmark_arguments(__doc__, repeats=7)
    ap.set_defaults(scenes=["hall", "spheres_and_boxes"])
    args = ap.parse_args(argv)
    import ssrlab

    r = open_renderer(args)
    print(f"{args.width}x{args.height}; GPU ms, medians of {args.repeats} renders after a warm-up")
    for scene_name in args.scenes:
        scene = ssrlab.scenes.load(scene_name)
        for name, kw in CASES.items():
            s = ssrlab.Settings(width=args.width, height=args.height, **{**BASE, **kw})
            r.render(scene, settings=s).color
            frames, walls, reads = [], [], []
            for _ in range(args.repeats):
                t0 = time.perf_counter()
                f = r.render(scene, settings=s)
                t1 = time.perf_counter()
                f.color
                t2 = time.perf_counter()
                frames.append(f)
                walls.append((t1 - t0) * 1e3)
                reads.append((t2 - t1) * 1e3)
            med = {k: statistics.median(f.timings[k] for f in frames) for k in frames[0].timings}
            sample = frames[-1].read("rays.sample")
            rays = int((sample[..., 0] > 0).sum())
            fetches = float(sample[..., 2].astype(np.float64).sum())
            print(f"{scene_name} {name} (skip={frames[-1].settings.skip}, "
                  f"deep_gbuffer={frames[-1].settings.deep_gbuffer}): "
                  + ", ".join(f"{k} {v:.3f}" for k, v in med.items()))
            print(f"   render() wall {statistics.median(walls):.2f} ms, color read {statistics.median(reads):.2f} ms, "
                  f"{rays} rays, {fetches / max(rays, 1):.1f} depth fetches per ray", flush=True)
            frames.clear()
    return 0


if __name__ == "__main__":
    sys.exit(main())
