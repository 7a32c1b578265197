"""Specular occlusion of unresolved rays: floor error against the converged reference, with and
without it, per glossy method and floor roughness, and the pass's time.

    python benchmarks/studies/occlusion.py [--width 320 --height 180 --repeats 5 --reference-rays 128]

For `hall` and `spheres_and_boxes` with floor roughness 0, 0.2 and 0.5 (the scenes'
`floor_roughness`), Hi-Z tracing, 1 G-buffer layer, fallback "environment": the stochastic
resolve (4 rays of the default sampling, "ggx"; 1 mirror ray per pixel at roughness 0), cone tracing and blurred mips,
each with Settings.specular_occlusion "off", "horizon" and "exit". Error over the floor's
pixels (the floor is the first object of both scenes; layer 0 shows it) against the converged
reference (`--reference-rays` VNDF rays per pixel, the same reference for every row of a
scene and roughness):
    relative MAE  = sum |image - reference| / sum reference   (every colour channel)
    relative bias = sum (image - reference) / sum reference
on the final colour, and the relative bias of the reflection term alone. Time: the GPU ms of the
specular_occlusion pass and of the whole frame, the occlusion modes of a method interleaved
round by round, --repeats rounds after the protocol's warm-up rounds; frame.stats'
occluded_misses / unresolved_rays. Every figure is a record and the table is rendered from them.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import ssrlab

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402

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
    bench = Bench("occlusion", args, r)
    print(f"{args.width}x{args.height}, Hi-Z, 1 layer, fallback 'environment'; floor pixels vs the converged reference "
          f"({args.reference_rays} VNDF rays); time: GPU ms of {args.repeats} rounds after {bench.warmup} warm-up "
          f"rounds, the occlusion modes interleaved\n")
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
                configs = {occ: ssrlab.Settings(width=args.width, height=args.height, method="hiz",
                                                specular_occlusion=occ, **kw) for occ in args.occlusion}
                for occ, s in configs.items():
                    f = r.render(scene, settings=s)
                    if truth is None:
                        truth = f.reference("converged", rays=args.reference_rays)
                        floor = (f.gbuffer.object_id[0] == FLOOR) & truth.reflective
                    mae, bias, rbias = floor_errors(f, truth, floor)
                    params = dict(scene=name, roughness=rough, method=label, occlusion=occ, width=args.width,
                                  height=args.height, reference_rays=args.reference_rays)
                    bench.record(params, "rel_mae", "", [mae])
                    bench.record(params, "bias", "%", [100 * bias])
                    bench.record(params, "refl_bias", "%", [100 * rbias])
                    if occ != "off":
                        bench.record(params, "occluded_misses", "rays", [f.stats.get("occluded_misses", 0)])
                        bench.record(params, "unresolved_rays", "rays", [f.stats.get("unresolved_rays", 0)])
                if args.repeats > 0:
                    times = bench.frames(r, scene, configs)
                    for occ, t in times.items():
                        params = dict(scene=name, roughness=rough, method=label, occlusion=occ, width=args.width,
                                      height=args.height, reference_rays=args.reference_rays)
                        bench.record_all(params, t, "ms", ("specular_occlusion", "total"))
                print(f"{name} roughness {rough:g} {label}: done", flush=True)
    bench.print_table(rows=("scene", "roughness", "method", "occlusion"),
                      order=["rel_mae", "bias", "refl_bias", "specular_occlusion", "total", "occluded_misses",
                             "unresolved_rays"], digits=3)


if __name__ == "__main__":
    main()
