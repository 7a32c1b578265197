"""The SVGF denoiser of the reflection (seed 003): error and cost per pass.

    python benchmarks/studies/svgf.py [--width 320 --height 180 --frames 8 --repeats 3]

spheres_and_boxes with floor roughness 0.2, static camera. For each tracer (linear SSR, pure BVH)
and each resolve (reuse_radius 0: one ray per pixel as seed 003 traces it; 1: ssrlab's default
3x3 neighbour-ray reuse), records the rmse of the glossy pixels' reflection against a 64-ray
converged reference (viewer "camera", shadows "map": the shading both tracers use) for:
1 ray; 4 rays; 1 ray accumulated over the frames (temporal_reflections); 1 ray + SVGF on a single
render (spatial only) and after the frames.
Then the GPU time of each SVGF pass: --repeats sequences after one untimed sequence (the
protocol's rounds), every frame 2..N of each a sample, with each frame's share of the frame
(device named; on llvmpipe the cores may be shared). Both tables are rendered from the records.
"""

from __future__ import annotations

import sys
from pathlib import Path

import ssrlab
from ssrlab import metrics

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402

PASSES = ("reproject", "svgf_temporal", "svgf_variance", "svgf_atrous")


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=3)
    ap.set_defaults(width=320, height=180)
    ap.add_argument("--frames", type=int, default=8)
    args = ap.parse_args()
    r = open_renderer(args)
    bench = Bench("svgf", args, r, warmup=1)
    scene = ssrlab.scenes.spheres_and_boxes(seed=1, count=8, floor_roughness=0.2)
    cams = [scene.camera] * args.frames
    print(f"spheres_and_boxes, floor roughness 0.2, {args.width}x{args.height}, static camera, {args.frames} frames; "
          f"rmse of the glossy pixels' reflection against a 64-ray converged reference")
    size = dict(width=args.width, height=args.height, frames=args.frames)
    for method in ("linear", "bvh"):
        for reuse in (0, 1):
            s = ssrlab.Settings(width=args.width, height=args.height, shadow_map_size=1024, method=method,
                                rays_per_pixel=1, reuse_radius=reuse)
            den = list(r.render_sequence(scene, cams, s.replace(denoise="svgf")))
            ref = den[-1].reference("converged", rays=64, viewer="camera", shadows="map")
            mask = ref.reflective & (den[-1].gbuffer.roughness[0] > 0.1)

            def e(frame):
                return metrics.rmse(frame.reflection, ref.reflection, mask)

            acc = list(r.render_sequence(scene, cams, s.replace(temporal_reflections=True)))
            cases = {"1 ray": r.render(scene, settings=s), "4 rays": r.render(scene, settings=s.replace(rays_per_pixel=4)),
                     "1 ray accumulated": acc[-1], "1 ray + SVGF single render": r.render(scene, settings=s.replace(
                         denoise="svgf")), f"1 ray + SVGF after {args.frames} frames": den[-1]}
            for case, frame in cases.items():
                bench.record(dict(method=method, reuse_radius=reuse, case=case, **size), "rmse_glossy", "", [e(frame)])
    bench.print_table(rows=("method", "reuse_radius"), columns="case", digits=4, note=False)

    s = ssrlab.Settings(width=args.width, height=args.height, shadow_map_size=1024, rays_per_pixel=1,
                        denoise="svgf")
    frames = {k: [] for k in (*PASSES, "total")}
    calls = {"n": 0}

    def sequence():
        seq = list(r.render_sequence(scene, cams, s))[1:]
        calls["n"] += 1
        if calls["n"] > bench.warmup:  # the untimed sequence pays compilation and first use
            for k in frames:
                frames[k].extend(f.timings[k] for f in seq)
        return {}

    bench.rounds({"svgf": sequence})
    params = dict(method="linear", reuse_radius=1, **size)
    timing = [bench.record(params, k, "ms", frames[k]) for k in (*PASSES, "total")]
    timing += [bench.record(params, f"{k}_share", "share", [a / b for a, b in zip(frames[k], frames["total"])])
               for k in PASSES]
    print(f"\nGPU ms of frames 2..{args.frames} of {args.repeats} sequences after an untimed one (linear, "
          f"reuse_radius 1), and each pass's share of its frame:")
    bench.print_table(timing, rows=("method", "reuse_radius"), digits=3)


if __name__ == "__main__":
    main()
