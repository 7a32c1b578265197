"""Hybrid reflections (issue 12): accuracy and cost of SSR alone, SSR + BVH fallback and pure BVH.

    python benchmarks/hybrid.py [--width 640 --height 360 --scenes hall spheres_and_boxes --repeats 5]

For each scene (hall with a mirror floor, floor_roughness=0, and its default view, whose floor
reflections leave the top of the screen; spheres_and_boxes as built), prints for SSR alone
(fallback "environment"), SSR + BVH fallback with and without the confidence test, and pure
BVH (method "bvh"): the reflection's PSNR against the converged reference (viewer "camera",
shadows "map": the shading the lit G-buffer and the BVH passes use, so that only what each
method finds differs), on reflective pixels and, for hall, on floor pixels; where the rays were
resolved (frame.fallback_stats); and the median GPU time of the frame and of its tracing passes
over --repeats renders after warm-up. All methods use origin_bias 0.0005 (see README).
"""

from __future__ import annotations

import numpy as np

import ssrlab
from ssrlab.metrics import psnr, thesis_error
from common import benchmark_arguments, median_timings, open_renderer

CONFIGS = {
    "SSR only (linear)": dict(fallback="environment"),
    "SSR + BVH fallback": dict(fallback="bvh"),
    "SSR + BVH fallback, no confidence": dict(fallback="bvh", fallback_confidence=False),
    "pure BVH": dict(method="bvh"),
}
TRACE_PASSES = ("trace_linear", "trace_hiz", "trace_bvh", "fallback_bvh")


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=5)
    ap.add_argument("--reference-rays", type=int, default=64, help="converged reference rays per glossy pixel")
    args = ap.parse_args()
    r = open_renderer(args)
    print(f"{args.width}x{args.height}, median of {args.repeats} renders after 2 warm-up renders\n")
    for name in args.scenes:
        scene = ssrlab.scenes.hall(floor_roughness=0.0) if name == "hall" else ssrlab.scenes.load(name)
        base = ssrlab.Settings(width=args.width, height=args.height, origin_bias=0.0005)
        f = r.render(scene, settings=base)
        ref = f.reference("converged", rays=args.reference_rays, viewer="camera", shadows="map")
        truth = ref.reflection[..., :3]
        masks = {"reflective": ref.reflective}
        if name == "hall":
            masks["floor"] = f.gbuffer.object_id[0] == 0
        print(f"{name}" + (" (mirror floor)" if name == "hall" else "") +
              f": {int(ref.reflective.sum())} reflective pixels")
        head = "  {:<36}".format("method") + "".join(f"{'PSNR ' + k:>17}" for k in masks)
        print(head + f"{'E refl.':>9}{'screen':>8}{'bvh':>6}{'env':>6}{'rej.':>6}{'frame ms':>10}{'trace ms':>10}")
        for label, kw in CONFIGS.items():
            st = base.replace(**kw)
            g = r.render(scene, settings=st)
            refl = g.reflection[..., :3]
            s = g.fallback_stats
            t = median_timings(r, scene, st, repeats=args.repeats)
            trace_ms = sum(t.get(p, 0.0) for p in TRACE_PASSES)
            row = "  {:<36}".format(label) + "".join(f"{psnr(refl, truth, mask=m):>14.2f} dB" for m in masks.values())
            row += f"{thesis_error(refl, truth, masks['reflective']):>9.4f}"
            row += f"{s['screen']:>8.2f}{s['bvh']:>6.2f}{s['environment']:>6.2f}{s['rejected']:>6.2f}"
            row += f"{t['total']:>10.1f}{trace_ms:>10.1f}"
            print(row)
        print()


if __name__ == "__main__":
    main()
