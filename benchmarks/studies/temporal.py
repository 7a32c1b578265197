"""Temporal accumulation of reflections: a static camera's sequence of 1-ray frames
against single frames of more rays, all measured against one converged reference (64 rays), and
the reproject and temporal passes' GPU time as a share of the frame; ray-result reuse over time
(temporal_ray_reuse) against the same rays without it; TAA against supersampling; and the cost
of every temporal pass as a share of the frame, all techniques on, over hall. Every figure is a
record: errors with one value (or one per frame where a mean over frames is reported), GPU times
with one sample per frame of the sequence after its first (which pays compilation and the empty
history); the tables are rendered from the records.

    python benchmarks/studies/temporal.py --width 160 --height 96 --frames 16
"""

from __future__ import annotations

import sys
from pathlib import Path
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402


def main() -> None:
    ap = benchmark_arguments(__doc__)
    ap.add_argument("--frames", type=int, default=16)
    ap.add_argument("--roughness", type=float, default=0.2, help="floor roughness of spheres_and_boxes")
    args = ap.parse_args()
    import ssrlab
    from ssrlab import metrics, scenes

    r = open_renderer(args)
    bench = Bench("temporal", args, r)
    size = dict(width=args.width, height=args.height, frames=args.frames)

    def err(study, case, values):
        bench.record(dict(study=study, case=case, **size), "rmse", "", values if isinstance(values, list) else [values])

    def times(study, case, frames, keys):
        out = {}
        for k in keys:
            out[k] = [f.timings.get(k, 0.0) for f in frames[1:]]
            bench.record(dict(study=study, case=case, **size), k, "ms", out[k])
        return out

    def share(study, case, part, whole):
        bench.record(dict(study=study, case=case, **size), "share_of_frame", "share",
                     [a / b for a, b in zip(part, whole)])

    scene = scenes.spheres_and_boxes(seed=1, count=8, floor_roughness=args.roughness)
    s = ssrlab.Settings(width=args.width, height=args.height, shadow_map_size=512, rays_per_pixel=1,
                        temporal_reflections=True)
    frames = list(r.render_sequence(scene, [scene.camera] * args.frames, s))
    ref = frames[-1].reference("converged", rays=64)
    mask = ref.reflective & (frames[-1].gbuffer.roughness[0] > 0.1)
    study = f"accumulation (spheres_and_boxes, floor roughness {args.roughness:g}, glossy pixels)"
    for k in sorted({1, 2, 4, 8, 16, args.frames} & set(range(1, args.frames + 1))):
        err(study, f"{k} accumulated 1-ray frames", metrics.rmse(frames[k - 1].reflection, ref.reflection, mask))
    for rays in (1, 4, 16):
        f = r.render(scene, settings=s.replace(rays_per_pixel=rays, temporal_reflections=False))
        err(study, f"single frame, {rays} rays", metrics.rmse(f.reflection, ref.reflection, mask))
    t = times(study, "accumulated 1-ray frames", frames, ("reproject", "temporal", "total"))
    share(study, "accumulated 1-ray frames: reproject + temporal",
          [a + b for a, b in zip(t["reproject"], t["temporal"])], t["total"])

    # TAA of a static camera over mirror_test against a 4x4-supersampled image of the same frame.
    scene = scenes.mirror_test()
    s = ssrlab.Settings(width=args.width, height=args.height, shadow_map_size=512)
    big = r.render(scene, settings=s.replace(width=4 * s.width, height=4 * s.height))
    truth = big.color.reshape(s.height, 4, s.width, 4, 3).mean(axis=(1, 3))
    study = "TAA (mirror_test, final image against 4x4 supersampling)"
    err(study, "no TAA", metrics.rmse(r.render(scene, settings=s).color, truth))
    for taa in ("thesis", "clamped"):
        frames = list(r.render_sequence(scene, [scene.camera] * args.frames, s.replace(taa=taa)))
        err(study, f"taa={taa!r} after {args.frames} frames", metrics.rmse(frames[-1].color, truth))
        t = times(study, f"taa={taa!r}", frames, ("taa", "reproject", "total"))  # thesis TAA: no reprojection
        share(study, f"taa={taa!r}: reproject + taa", [a + b for a, b in zip(t["taa"], t["reproject"])], t["total"])

    # Ray-result reuse over time (seed 000, 4.4): 1 ray per frame, the previous frame's rays join.
    scene = scenes.spheres_and_boxes(seed=1, count=8, floor_roughness=args.roughness)
    s = ssrlab.Settings(width=args.width, height=args.height, shadow_map_size=512, rays_per_pixel=1)
    n = min(args.frames, 8)
    off = list(r.render_sequence(scene, [scene.camera] * n, s))
    on = list(r.render_sequence(scene, [scene.camera] * n, s.replace(temporal_ray_reuse=True)))
    ref = off[-1].reference("converged", rays=64)
    mask = ref.reflective & (off[-1].gbuffer.roughness[0] > 0.1)
    study = f"ray reuse over time (frames 2..{n}, glossy pixels)"
    err(study, "reuse off", [metrics.rmse(f.reflection, ref.reflection, mask) for f in off[1:]])
    err(study, "reuse on", [metrics.rmse(f.reflection, ref.reflection, mask) for f in on[1:]])
    err(study, "2-ray frames", [metrics.rmse(r.render(scene, settings=s.replace(rays_per_pixel=2, seed=k)).reflection,
                                             ref.reflection, mask) for k in range(1, n)])
    times(study, "reuse off", off, ("resolve",))
    times(study, "reuse on", on, ("resolve",))

    # Every temporal pass's share of the frame, all techniques on, over hall.
    scene = scenes.hall()
    s = ssrlab.Settings(width=args.width, height=args.height, shadow_map_size=1024, rays_per_pixel=1,
                        temporal_reflections=True, temporal_clamp=1.0, temporal_ray_reuse=True,
                        bounces="history", taa="clamped")
    frames = list(r.render_sequence(scene, [scene.camera] * args.frames, s))
    plain = list(r.render_sequence(scene, [scene.camera] * args.frames, s.replace(
        temporal_reflections=False, temporal_ray_reuse=False, bounces="single", taa="off")))
    study = "hall, every temporal technique"
    t = times(study, "all on", frames, ("reproject", "temporal", "taa", "resolve", "total"))
    for k in ("reproject", "temporal", "taa"):
        share(study, f"all on: {k}", t[k], t["total"])
    times(study, "all off", plain, ("resolve", "total"))

    print(f"{args.width}x{args.height}; rmse against 64-ray converged references (or 4x4 supersampling); one value, "
          f"or the frames' values\n")
    bench.print_table([x for x in bench.recorder.records if x["metric"] == "rmse"], rows=("study", "case"), digits=4)
    print("\nGPU ms of frames 2..N (the first pays compilation and an empty history); share_of_frame: each "
          "frame's part over its total\n")
    bench.print_table([x for x in bench.recorder.records if x["metric"] != "rmse"], rows=("study", "case"), digits=3)


if __name__ == "__main__":
    main()
