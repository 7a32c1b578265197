"""The SVGF denoiser of the reflection (seed 003): error and cost per pass.

    python benchmarks/svgf.py [--width 320 --height 180 --frames 8 --repeats 3]

spheres_and_boxes with floor roughness 0.2, static camera. For each tracer (linear SSR, pure BVH)
and each resolve (reuse_radius 0: one ray per pixel as seed 003 traces it; 1: ssrlab's default
3x3 neighbour-ray reuse), prints the rmse of the glossy pixels' reflection against a 64-ray
converged reference (viewer "camera", shadows "map": the shading both tracers use) for:
1 ray; 4 rays; 1 ray accumulated over the frames (temporal_reflections); 1 ray + SVGF on a single
render (spatial only) and after the frames.
Then the GPU time of each SVGF pass: medians over frames 2..N of --repeats sequences, with
their share of the frame (device named; on llvmpipe the cores may be shared).
"""

from __future__ import annotations

import statistics

import ssrlab
from ssrlab import metrics
from common import benchmark_arguments, open_renderer

PASSES = ("reproject", "svgf_temporal", "svgf_variance", "svgf_atrous")


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=3)
    ap.set_defaults(width=320, height=180)
    ap.add_argument("--frames", type=int, default=8)
    args = ap.parse_args()
    r = open_renderer(args)
    scene = ssrlab.scenes.spheres_and_boxes(seed=1, count=8, floor_roughness=0.2)
    cams = [scene.camera] * args.frames
    print(f"spheres_and_boxes, floor roughness 0.2, {args.width}x{args.height}, static camera, {args.frames} frames; "
          f"rmse of the glossy pixels' reflection against a 64-ray converged reference")
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
            one = r.render(scene, settings=s)
            four = r.render(scene, settings=s.replace(rays_per_pixel=4))
            single = r.render(scene, settings=s.replace(denoise="svgf"))
            print(f"  {method:<6} reuse_radius {reuse}: 1 ray {e(one):.4f}, 4 rays {e(four):.4f}, "
                  f"1 ray accumulated {e(acc[-1]):.4f}, 1 ray + SVGF single render {e(single):.4f}, "
                  f"after {args.frames} frames {e(den[-1]):.4f}")
    s = ssrlab.Settings(width=args.width, height=args.height, shadow_map_size=1024, rays_per_pixel=1,
                        denoise="svgf")
    frames = [f for _ in range(args.repeats) for f in list(r.render_sequence(scene, cams, s))[1:]]
    med = {k: statistics.median(f.timings[k] for f in frames) for k in (*PASSES, "total")}
    iqr = {k: statistics.quantiles([f.timings[k] for f in frames], n=4) for k in PASSES}
    print(f"GPU ms, median over frames 2..{args.frames} of {args.repeats} sequences (linear, reuse_radius 1):")
    for k in PASSES:
        q = iqr[k]
        print(f"  {k:<14} {med[k]:7.3f} ms (IQR {q[0]:.3f}-{q[2]:.3f}), {100 * med[k] / med['total']:4.1f} % of the frame")
    print(f"  frame          {med['total']:7.3f} ms")


if __name__ == "__main__":
    main()
