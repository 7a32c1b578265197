"""Temporal accumulation of reflections: a static camera's sequence of 1-ray frames
against single frames of more rays, all measured against one converged reference (64 rays), and
the reproject and temporal passes' GPU time as a share of the frame; ray-result reuse over time
(temporal_ray_reuse) against the same rays without it; TAA against supersampling; and the cost
of every temporal pass as a share of the frame, all techniques on, over hall.

    python benchmarks/temporal.py --width 160 --height 96 --frames 16
"""

from __future__ import annotations

import statistics

from common import benchmark_arguments, open_renderer


def main() -> None:
    ap = benchmark_arguments(__doc__)
    ap.add_argument("--frames", type=int, default=16)
    ap.add_argument("--roughness", type=float, default=0.2, help="floor roughness of spheres_and_boxes")
    args = ap.parse_args()
    import ssrlab
    from ssrlab import metrics, scenes

    r = open_renderer(args)
    scene = scenes.spheres_and_boxes(seed=1, count=8, floor_roughness=args.roughness)
    s = ssrlab.Settings(width=args.width, height=args.height, shadow_map_size=512, rays_per_pixel=1,
                        temporal_reflections=True)
    frames = list(r.render_sequence(scene, [scene.camera] * args.frames, s))
    ref = frames[-1].reference("converged", rays=64)
    mask = ref.reflective & (frames[-1].gbuffer.roughness[0] > 0.1)
    print(f"spheres_and_boxes, floor roughness {args.roughness}, {args.width}x{args.height}, rmse of the "
          f"reflection on glossy pixels against a 64-ray converged reference")
    ks = sorted({1, 2, 4, 8, 16, args.frames} & set(range(1, args.frames + 1)))
    print("  accumulated 1-ray frames: " +
          ", ".join(f"{k} frames {metrics.rmse(frames[k - 1].reflection, ref.reflection, mask):.4f}" for k in ks))
    for rays in (1, 4, 16):
        f = r.render(scene, settings=s.replace(rays_per_pixel=rays, temporal_reflections=False))
        print(f"  single frame, {rays:2d} rays: {metrics.rmse(f.reflection, ref.reflection, mask):.4f}")
    med = {k: statistics.median(f.timings[k] for f in frames[1:]) for k in ("reproject", "temporal", "total")}
    print(f"GPU ms (median of frames 2..{args.frames}): reproject {med['reproject']:.3f}, temporal "
          f"{med['temporal']:.3f}, frame {med['total']:.3f}: "
          f"{100 * (med['reproject'] + med['temporal']) / med['total']:.1f} % of the frame")

    # TAA of a static camera over mirror_test against a 4x4-supersampled image of the same frame.
    scene = scenes.mirror_test()
    s = ssrlab.Settings(width=args.width, height=args.height, shadow_map_size=512)
    big = r.render(scene, settings=s.replace(width=4 * s.width, height=4 * s.height))
    truth = big.color.reshape(s.height, 4, s.width, 4, 3).mean(axis=(1, 3))
    print(f"mirror_test, {args.width}x{args.height}, rmse of the final image against 4x4 supersampling")
    print(f"  no TAA: {metrics.rmse(r.render(scene, settings=s).color, truth):.4f}")
    for taa in ("thesis", "clamped"):
        frames = list(r.render_sequence(scene, [scene.camera] * args.frames, s.replace(taa=taa)))
        ms = statistics.median(f.timings["taa"] + f.timings.get("reproject", 0.0) for f in frames[1:])  # thesis TAA: no reprojection
        total = statistics.median(f.timings["total"] for f in frames[1:])
        print(f"  taa={taa!r} after {args.frames} frames: {metrics.rmse(frames[-1].color, truth):.4f}; "
              f"reproject + taa {ms:.3f} ms of {total:.3f} ms ({100 * ms / total:.1f} %)")

    # Ray-result reuse over time (seed 000, 4.4): 1 ray per frame, the previous frame's rays join.
    scene = scenes.spheres_and_boxes(seed=1, count=8, floor_roughness=args.roughness)
    s = ssrlab.Settings(width=args.width, height=args.height, shadow_map_size=512, rays_per_pixel=1)
    n = min(args.frames, 8)
    off = list(r.render_sequence(scene, [scene.camera] * n, s))
    on = list(r.render_sequence(scene, [scene.camera] * n, s.replace(temporal_ray_reuse=True)))
    ref = off[-1].reference("converged", rays=64)
    mask = ref.reflective & (off[-1].gbuffer.roughness[0] > 0.1)
    e_off = statistics.mean(metrics.rmse(f.reflection, ref.reflection, mask) for f in off[1:])
    e_on = statistics.mean(metrics.rmse(f.reflection, ref.reflection, mask) for f in on[1:])
    two = statistics.mean(metrics.rmse(r.render(scene, settings=s.replace(rays_per_pixel=2, seed=k)).reflection,
                                       ref.reflection, mask) for k in range(1, n))
    res_off = statistics.median(f.timings["resolve"] for f in off[1:])
    res_on = statistics.median(f.timings["resolve"] for f in on[1:])
    print(f"ray reuse over time, mean rmse of frames 2..{n}: off {e_off:.4f}, on {e_on:.4f} "
          f"(2-ray frames {two:.4f}); resolve {res_off:.3f} -> {res_on:.3f} ms")

    # Every temporal pass's share of the frame, all techniques on, over hall.
    scene = scenes.hall()
    s = ssrlab.Settings(width=args.width, height=args.height, shadow_map_size=1024, rays_per_pixel=1,
                        temporal_reflections=True, temporal_clamp=1.0, temporal_ray_reuse=True,
                        bounces="history", taa="clamped")
    frames = list(r.render_sequence(scene, [scene.camera] * args.frames, s))
    plain = list(r.render_sequence(scene, [scene.camera] * args.frames, s.replace(
        temporal_reflections=False, temporal_ray_reuse=False, bounces="single", taa="off")))
    med = {k: statistics.median(f.timings[k] for f in frames[1:]) for k in ("reproject", "temporal", "taa", "resolve", "total")}
    res0 = statistics.median(f.timings["resolve"] for f in plain[1:])
    tot0 = statistics.median(f.timings["total"] for f in plain[1:])
    print(f"hall, {args.width}x{args.height}, all temporal techniques on, GPU ms (median of frames 2..{args.frames}):")
    for k in ("reproject", "temporal", "taa"):
        print(f"  {k}: {med[k]:.3f} ms, {100 * med[k] / med['total']:.1f} % of the frame")
    print(f"  resolve with ray reuse and bounces from history: {med['resolve']:.3f} ms vs {res0:.3f} ms without "
          f"(+{100 * (med['resolve'] - res0) / med['total']:.1f} % of the frame)")
    print(f"  frame: {med['total']:.3f} ms vs {tot0:.3f} ms with every temporal technique off")


if __name__ == "__main__":
    main()
