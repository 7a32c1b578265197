"""GPU time of the converged reference: rays traced against the triangles and shaded.

    python benchmarks/reference_speed.py [--width 640 --height 360 --rays 256]

Prints the reference pass's GPU time and the rays per second it reached, per scene.
"""

from __future__ import annotations

import numpy as np

import ssrlab
from common import benchmark_arguments, open_renderer


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=None)
    ap.add_argument("--rays", type=int, default=256)
    args = ap.parse_args()
    r = open_renderer(args)
    print(f"{args.width}x{args.height}, {args.rays} rays per reflective pixel (1 for mirrors)\n")
    print(f"{'scene':<18} {'triangles':>9} {'rays traced':>12} {'GPU s':>7} {'Mrays/s':>8}")
    for name in args.scenes:
        scene = ssrlab.scenes.load(name)
        frame = r.render(scene, width=args.width, height=args.height, method="off")
        frame.reference("converged", rays=1)  # warm-up: BVH build, shader compile
        ref = frame.reference("converged", rays=args.rays)
        g = frame.gbuffer
        reflective = ssrlab.reference.reflective_mask(frame)
        mirror = reflective & (g.roughness[0] ** 2 < 1e-4)
        rays = int(mirror.sum() + (reflective & ~mirror).sum() * args.rays)
        seconds = ref.timings["reference"] / 1000
        print(f"{name:<18} {scene.triangle_count:>9} {rays:>12} {seconds:>7.2f} {rays / seconds / 1e6:>8.2f}")


if __name__ == "__main__":
    main()
