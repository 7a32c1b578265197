"""Memory of kept and dropped frames: N renders whose frames are all kept alive, then
dropped; prints process RSS (/proc/self/statm) at the start (after a warm-up), with every frame
kept and after dropping them, the bytes each frame holds (Frame.gpu_bytes) and RSS per kept frame.

    python benchmarks/memory.py                  # 1000 renders at 64x48, spheres_and_boxes
    python benchmarks/memory.py --renders 400 --width 320 --height 180
"""

from __future__ import annotations

import gc
import os
import time

from common import benchmark_arguments, open_renderer

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

    renderer = open_renderer(args)
    scene = ssrlab.scenes.load(args.scenes[0])
    s = ssrlab.Settings(width=args.width, height=args.height, shadow_map_size=args.shadow_map_size)
    for _ in range(args.warmup):
        renderer.render(scene, settings=s).color
    gc.collect()
    start = rss()
    t0 = time.perf_counter()
    kept = [renderer.render(scene, settings=s) for _ in range(args.renders)]
    seconds = time.perf_counter() - t0
    full = rss()
    per_frame_api = sum(f.gpu_bytes for f in kept) / len(kept)
    live = len(renderer.live_frames)
    del kept
    gc.collect()
    end = rss()
    print(f"{args.renders} renders of {args.scenes[0]} at {args.width}x{args.height} "
          f"(shadow map {args.shadow_map_size}^2) in {seconds:.1f} s, frames kept alive then dropped")
    print(f"RSS: start {start / MIB:.1f} MiB, {live} frames kept {full / MIB:.1f} MiB, "
          f"after dropping them {end / MIB:.1f} MiB ({100 * (end - start) / start:+.1f} % of the start)")
    print(f"per kept frame: Frame.gpu_bytes {per_frame_api / MIB:.3f} MiB, RSS {(full - start) / args.renders / MIB:.3f} MiB; "
          f"renderer scratch (shared) {renderer.scratch_bytes / MIB:.1f} MiB, "
          f"renderer.gpu_bytes now {renderer.gpu_bytes / MIB:.1f} MiB, live frames now {len(renderer.live_frames)}")
    ok = end <= 1.10 * start and per_frame_api < MIB and (full - start) / args.renders < MIB
    print("verdict:", "within 10 % of the start and < 1 MiB per kept frame" if ok else "NOT within the bounds")


if __name__ == "__main__":
    main()
