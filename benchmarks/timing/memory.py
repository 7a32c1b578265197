"""Memory of kept and dropped frames: N renders whose frames are all kept alive, then
dropped; prints process RSS (/proc/self/statm) at the start (after a warm-up), with every frame
kept and after dropping them, the bytes each frame holds (Frame.gpu_bytes) and RSS per kept frame,
each a record (one value a run), with every render's wall milliseconds (the protocol's rounds, no
warm-up rounds: --warmup renders come first); the table is rendered from the records and the
verdict (within 10 % of the start and under 1 MiB per kept frame) from the same figures.

    python benchmarks/timing/memory.py                  # 1000 renders at 64x48, spheres_and_boxes
    python benchmarks/timing/memory.py --renders 400 --width 320 --height 180
"""

from __future__ import annotations

import sys
from pathlib import Path
import gc
import os

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402

MIB = 1 << 20


def rss() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def main() -> None:
    ap = benchmark_arguments(__doc__)
    ap.set_defaults(width=64, height=48, scenes=["spheres_and_boxes"])
    ap.add_argument("--renders", type=int, default=1000)
    ap.add_argument("--warmup", type=int, default=30)
    ap.add_argument("--shadow-map-size", type=int, default=2048)
    args = ap.parse_args()
    import ssrlab
    from ssrlab.lab.protocol import Bench

    renderer = open_renderer(args)
    bench = Bench("memory", args, renderer, repeats=args.renders, warmup=0)
    scene = ssrlab.scenes.load(args.scenes[0])
    s = ssrlab.Settings(width=args.width, height=args.height, shadow_map_size=args.shadow_map_size)
    for _ in range(args.warmup):
        renderer.render(scene, settings=s).color
    gc.collect()
    start = rss()
    kept = []
    ms = bench.calls({"render": lambda: kept.append(renderer.render(scene, settings=s))})["render"]
    full = rss()
    per_frame_api = sum(f.gpu_bytes for f in kept) / len(kept)
    live = len(renderer.live_frames)
    kept.clear()
    gc.collect()
    end = rss()
    params = dict(scene=args.scenes[0], width=args.width, height=args.height, renders=args.renders,
                  shadow_map_size=args.shadow_map_size)
    bench.record(params, "render_wall", "ms", ms)
    for metric, value in (("rss_start", start), ("rss_kept", full), ("rss_after_drop", end),
                          ("gpu_bytes_per_frame", per_frame_api), ("rss_per_kept_frame", (full - start) / args.renders),
                          ("renderer_scratch", renderer.scratch_bytes), ("renderer_gpu_bytes", renderer.gpu_bytes)):
        bench.record(params, metric, "MiB", [value / MIB])
    bench.record(params, "frames_kept", "frames", [live])
    bench.record(params, "live_frames_after_drop", "frames", [len(renderer.live_frames)])
    bench.record(params, "rss_after_drop_over_start", "x", [end / start])
    print(f"{args.renders} renders of {args.scenes[0]} at {args.width}x{args.height} "
          f"(shadow map {args.shadow_map_size}^2), frames kept alive then dropped")
    bench.print_table(rows=("scene", "renders"), digits=3)
    ok = end <= 1.10 * start and per_frame_api < MIB and (full - start) / args.renders < MIB
    print("verdict:", "met: within 10 % of the start and < 1 MiB per kept frame" if ok else
          "not met: NOT within the bounds (10 % of the start, 1 MiB per kept frame)")


if __name__ == "__main__":
    main()
