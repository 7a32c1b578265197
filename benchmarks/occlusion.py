"""Specular occlusion of unresolved rays: floor error against the converged reference, with and
without it, per glossy method and floor roughness, and the pass's time.

    python benchmarks/occlusion.py [--width 320 --height 180 --repeats 5 --reference-rays 128]

For `hall` and `spheres_and_boxes` with floor roughness 0, 0.2 and 0.5 (the scenes'
`floor_roughness`), Hi-Z tracing, 1 G-buffer layer, fallback "environment": the stochastic
resolve (4 rays of the default sampling, "ggx"; 1 mirror ray per pixel at roughness 0), cone tracing and blurred mips,
each with Settings.specular_occlusion "off", "horizon" and "exit". Error over the floor's
pixels (the floor is the first object of both scenes; layer 0 shows it) against the converged
reference (`--reference-rays` VNDF rays per pixel, the same reference for every row of a
scene and roughness):
    relative MAE  = sum |image - reference| / sum reference   (every colour channel)
    relative bias = sum (image - reference) / sum reference
on the final colour, and the relative bias of the reflection term alone. Time: the median GPU
ms of the specular_occlusion pass over --repeats renders after 2 warm-up renders, and of the
whole frame; frame.stats' occluded_misses / unresolved_rays.
"""

from __future__ import annotations

import datetime

import numpy as np

import ssrlab
from common import benchmark_arguments, median_timings, open_renderer

ROUGHNESS = (0.0, 0.2, 0.5)
METHODS = {
    "stochastic": dict(rays_per_pixel=4),  # the default sampling ("ggx"), as the issue measured
    "cone": dict(glossy="cone"),
    "blur_mips": dict(glossy="blur_mips"),
}
OCCLUSION = ("off", "horizon", "exit")
FLOOR = 0  # object index of the floor: both scenes add it first


def floor_errors(frame, truth, floor: np.ndarray) -> tuple[float, float, float]:
    a, b = frame.color[floor].astype(np.float64), truth.color[floor].astype(np.float64)
    ra, rb = frame.reflection[floor].astype(np.float64), truth.reflection[floor].astype(np.float64)
    return (float(np.abs(a - b).sum() / b.sum()), float((a - b).sum() / b.sum()),
            float((ra - rb).sum() / max(rb.sum(), 1e-12)))


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=5)
    ap.add_argument("--reference-rays", type=int, default=128)
    ap.add_argument("--roughness", type=float, nargs="+", default=list(ROUGHNESS))
    ap.add_argument("--methods", nargs="+", default=list(METHODS), choices=list(METHODS))
    ap.add_argument("--occlusion", nargs="+", default=list(OCCLUSION), choices=list(OCCLUSION))
    ap.add_argument("--sampling", default=None, choices=("ggx", "vndf"),
                    help="sampling of the stochastic rays (default: Settings' default)")
    args = ap.parse_args()
    r = open_renderer(args)
    print(f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC; {args.width}x{args.height}, Hi-Z, "
          f"1 layer, fallback 'environment'; floor pixels vs the converged reference ({args.reference_rays} VNDF "
          f"rays); time: median GPU ms of {args.repeats} renders after 2 warm-ups\n")
    print(f"{'scene':<18} {'rough':>5} {'method':<11} {'occlusion':<9} {'rel MAE':>8} {'bias':>7} "
          f"{'refl bias':>9} {'occl ms':>8} {'frame ms':>9} {'occluded/unresolved':>20}")
    for name in args.scenes:
        for rough in args.roughness:
            scene = ssrlab.scenes.load(name, floor_roughness=rough)
            truth = None
            for label, kw in METHODS.items():
                if label not in args.methods:
                    continue
                if label == "stochastic" and args.sampling:
                    kw = dict(kw, sampling=args.sampling)
                if rough == 0.0 and label == "stochastic":
                    kw = dict(rays_per_pixel=1)  # a mirror: one ray, any sampling
                for occ in args.occlusion:
                    s = ssrlab.Settings(width=args.width, height=args.height, method="hiz",
                                        specular_occlusion=occ, **kw)
                    f = r.render(scene, settings=s)
                    if truth is None:
                        truth = f.reference("converged", rays=args.reference_rays)
                        floor = (f.gbuffer.object_id[0] == FLOOR) & truth.reflective
                    mae, bias, rbias = floor_errors(f, truth, floor)
                    st = f.stats
                    counts = (f"{int(st.get('occluded_misses', 0))}/{int(st.get('unresolved_rays', 0))}"
                              if occ != "off" else "-")
                    t = median_timings(r, scene, s, repeats=args.repeats) if args.repeats > 0 else {}
                    print(f"{name:<18} {rough:>5.2f} {label:<11} {occ:<9} {mae:>8.4f} {bias * 100:>+6.1f}% "
                          f"{rbias * 100:>+8.1f}% {t.get('specular_occlusion', 0.0):>8.2f} "
                          f"{t.get('total', float('nan')):>9.2f} {counts:>20}", flush=True)
        print()


if __name__ == "__main__":
    main()
