"""Samples per second of the converged reference, beside Mitsuba 3's on the same rays (issue: the
reference on the CPU device through Embree).

    python benchmarks/reference_speed.py [--width 320 --height 180 --rays 256 --repeats 3]

For each scene (the Mitsuba cross-check scene with a 0.3-rough floor, and spheres_and_boxes) and
the frame's reflective pixels (one ray for mirror pixels, `--rays` for the rest), it times:

* ssrlab's converged reference with tracer="cpu" (rays through Embree, ray generation and
  shading in C++ on every core: what "auto" takes on the CPU device), tracer="embree" (rays
  through Embree, ray generation and shading in GLSL) and tracer="glsl" (the BVH traversed in
  GLSL), wall-clock seconds after a warm-up reference (BVH build, shader compilation) — on the
  CPU device all run on the CPU;
* Mitsuba 3's path tracer (llvm_ad_rgb, max_depth 3: camera, floor, object, light, with next-
  event estimation) on the same pixel-centre camera rays of the same reflective pixels, with the
  same number of samples per pixel (after a warm-up run that compiles its kernels).

Samples per second = (rays asked per reflective pixel, summed over them) / seconds. Medians of
`--repeats` interleaved runs, with each one's spread (min-max over the runs, as a percentage of
the median) so a noisy machine shows. Mitsuba sees spheres_and_boxes without its ambient term and with a
black environment (its comparable form, ssrlab.crosscheck.check_comparable); ssrlab renders the
scene as it is. Dr.Jit uses `--jit-threads` worker threads (default: every core, as ssrlab's
Embree and llvmpipe do).
"""

from __future__ import annotations

import os
import statistics
import time

import numpy as np

import ssrlab
from common import benchmark_arguments, open_renderer
from ssrlab import crosscheck as cc


def mitsuba_on_pixels(ms, pixels: np.ndarray, spp: np.ndarray, seed: int = 0) -> float:
    """Seconds for Mitsuba's path tracer on pixel-centre rays of `pixels` ((n, 2) x, y), spp[i] each."""
    mi = cc.load_mitsuba()  # the module, its variant already set
    import drjit as dr

    integrator = mi.load_dict({"type": "path", "max_depth": 3, "hide_emitters": False})
    xs = np.repeat(pixels[:, 0], spp).astype(np.float32) + 0.5
    ys = np.repeat(pixels[:, 1], spp).astype(np.float32) + 0.5
    t = time.perf_counter()
    n = len(xs)
    ray, _ = ms.sensor.sample_ray_differential(0.0, 0.5, mi.Point2f(mi.Float(xs / ms.width),
                                                                     mi.Float(ys / ms.height)), mi.Point2f(0.5, 0.5))
    sampler = mi.load_dict({"type": "independent"})
    sampler.seed(seed, n)
    L, _, _ = integrator.sample(ms.scene, sampler, ray, None, True)
    dr.eval(L)
    np.asarray(L[0])
    return time.perf_counter() - t


def comparable(scene):
    scene.ambient = (0.0, 0.0, 0.0)
    scene.environment = ssrlab.Environment.constant((0.0, 0.0, 0.0))
    return scene


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=3)
    ap.set_defaults(width=320, height=180, scenes=["crosscheck", "spheres_and_boxes"])
    ap.add_argument("--rays", type=int, default=256)
    ap.add_argument("--roughness", type=float, default=0.3, help="the cross-check scene's floor roughness")
    ap.add_argument("--jit-threads", type=int, default=os.cpu_count())
    ap.add_argument("--no-mitsuba", action="store_true")
    ap.add_argument("--tracers", nargs="+", default=["cpu", "embree", "glsl"])
    args = ap.parse_args()
    r = open_renderer(args)
    mitsuba = not args.no_mitsuba
    if mitsuba:
        try:
            cc.JIT_THREADS = args.jit_threads
            cc.load_mitsuba()
            print(cc.mitsuba_version(), f"({args.jit_threads} Dr.Jit threads)")
        except ImportError as e:
            print(f"Mitsuba unavailable ({e}): ssrlab only")
            mitsuba = False
    print(f"{args.width}x{args.height}, {args.rays} samples per rough reflective pixel (1 for mirrors), "
          f"{os.cpu_count()} cores, medians of {args.repeats}\n")
    cols = [f"{t} s" for t in args.tracers] + [f"{t} Ms/s" for t in args.tracers]
    if mitsuba:
        cols += ["Mitsuba s", "Mitsuba Ms/s"] + [f"{t}/Mitsuba" for t in args.tracers]
    print(f"{'scene':<20} {'pixels':>7} {'samples':>10} " + " ".join(f"{c:>13}" for c in cols))
    for name in args.scenes:
        scene = cc.crosscheck_scene(args.roughness) if name == "crosscheck" else ssrlab.scenes.load(name)
        frame = r.render(scene, width=args.width, height=args.height, method="off")
        g = frame.gbuffer
        reflective = ssrlab.reference.reflective_mask(frame)
        mirror = reflective & (g.roughness[0] ** 2 < 1e-4)
        spp_map = np.where(mirror, 1, args.rays)[reflective]
        samples = int(spp_map.sum())
        ys, xs = np.nonzero(reflective)
        pixels = np.stack([xs, ys], -1)
        for t in args.tracers:
            frame.reference("converged", rays=1, tracer=t)  # warm-up: BVH / Embree scene, shaders
        ms = None
        if mitsuba:
            ms = cc.mitsuba_scene(comparable(scene.copy()), width=args.width, height=args.height)
            mitsuba_on_pixels(ms, pixels[:64], spp_map[:64])  # warm-up: kernel compilation
        runs: dict[str, list[float]] = {k: [] for k in args.tracers + ["mitsuba"]}
        for rep in range(args.repeats):
            for t in args.tracers:
                start = time.perf_counter()
                frame.reference("converged", rays=args.rays, tracer=t, seed=rep)
                runs[t].append(time.perf_counter() - start)
            if mitsuba:
                runs["mitsuba"].append(mitsuba_on_pixels(ms, pixels, spp_map, seed=rep))
        sec = {k: statistics.median(v) for k, v in runs.items() if v}
        vals = [f"{sec[t]:13.2f}" for t in args.tracers] + [f"{samples / sec[t] / 1e6:13.3f}" for t in args.tracers]
        if mitsuba:
            vals += [f"{sec['mitsuba']:13.2f}", f"{samples / sec['mitsuba'] / 1e6:13.3f}"]
            vals += [f"{sec['mitsuba'] / sec[t]:12.2f}x" for t in args.tracers]
        print(f"{name:<20} {int(reflective.sum()):>7} {samples:>10} " + " ".join(vals))
        spread = {k: (max(v) - min(v)) / statistics.median(v) for k, v in runs.items() if v}
        print(f"{'':<20} spread (max-min)/median: " + ", ".join(f"{k} {100 * v:.0f}%" for k, v in spread.items()))
        if "cpu" in args.tracers:
            ref = frame.reference("converged", rays=args.rays, tracer="cpu")
            st = ref.timings
            print(f"{'':<20} cpu stages (ms): trace and shade {st['reference.cpu']:.0f}, transfer "
                  f"{st['reference.transfer']:.0f}; {ref.rays_traced} rays traced "
                  f"({ref.rays_traced / st['reference.cpu'] / 1e3:.2f} M rays/s with their shading)")
        if "embree" in args.tracers:
            ref = frame.reference("converged", rays=args.rays, tracer="embree")
            st = ref.timings
            print(f"{'':<20} embree stages (ms): shade (GLSL) {st['reference.shade']:.0f}, intersect (Embree) "
                  f"{st['reference.intersect']:.0f}, transfer {st['reference.transfer']:.0f}; "
                  f"{ref.rays_traced} rays traced")


if __name__ == "__main__":
    main()
