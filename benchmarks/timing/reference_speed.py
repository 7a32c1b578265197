"""Samples per second of the converged reference, beside Mitsuba 3's on the same rays (issue: the
reference on the CPU device through Embree).

    python benchmarks/timing/reference_speed.py [--width 320 --height 180 --rays 256 --repeats 3]

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

Samples per second = (rays asked per reflective pixel, summed over them) / seconds, one value
per round. `--repeats` rounds of the protocol (Bench.calls), the tracers and Mitsuba interleaved
within each round, each round with its own seed; every figure is a record with its samples, and
the table is rendered from them (median [interquartile range]), so a noisy machine shows. Mitsuba sees spheres_and_boxes without its ambient term and with a
black environment (its comparable form, ssrlab.crosscheck.check_comparable); ssrlab renders the
scene as it is. Dr.Jit uses `--jit-threads` worker threads (default: every core, as ssrlab's
Embree and llvmpipe do).
"""

from __future__ import annotations

import sys
from pathlib import Path
import os
import time

import numpy as np

import ssrlab

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402
from ssrlab import crosscheck as cc  # noqa: E402


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
    bench = Bench("reference_speed", args, r, warmup=0)  # the warm-ups below are lighter than a round
    print(f"{args.width}x{args.height}, {args.rays} samples per rough reflective pixel (1 for mirrors), "
          f"{os.cpu_count()} cores, {args.repeats} rounds\n")
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
        seed = {"round": -1}

        def reference(t):
            def run():
                if t == args.tracers[0]:
                    seed["round"] += 1  # each round its own seed, the same for every side of it
                frame.reference("converged", rays=args.rays, tracer=t, seed=seed["round"])
            return run

        calls = {t: reference(t) for t in args.tracers}
        if mitsuba:
            calls["mitsuba"] = lambda: mitsuba_on_pixels(ms, pixels, spp_map, seed=seed["round"])
        runs = bench.calls(calls)
        params = dict(scene=name, pixels=int(reflective.sum()), samples=samples, width=args.width,
                      height=args.height, rays=args.rays)
        for k, v in runs.items():
            p = {**params, "tracer": k}
            bench.record(p, "seconds", "s", [x / 1e3 for x in v])
            bench.record(p, "samples_per_s", "Ms/s", [samples / (x / 1e3) / 1e6 for x in v], better="higher")
            if mitsuba and k != "mitsuba":
                # round by round: Mitsuba's seconds over this tracer's in the same round
                bench.record(p, "over_mitsuba", "x", [m / x for m, x in zip(runs["mitsuba"], v)], better="higher")
        if "cpu" in args.tracers:
            ref = frame.reference("converged", rays=args.rays, tracer="cpu")
            st = ref.timings
            p = {**params, "tracer": "cpu"}
            bench.record(p, "stage: trace and shade", "ms", [st["reference.cpu"]])
            bench.record(p, "stage: transfer", "ms", [st["reference.transfer"]])
            bench.record(p, "rays_traced", "rays", [ref.rays_traced])
        if "embree" in args.tracers:
            ref = frame.reference("converged", rays=args.rays, tracer="embree")
            st = ref.timings
            p = {**params, "tracer": "embree"}
            bench.record(p, "stage: shade (GLSL)", "ms", [st["reference.shade"]])
            bench.record(p, "stage: intersect (Embree)", "ms", [st["reference.intersect"]])
            bench.record(p, "stage: transfer", "ms", [st["reference.transfer"]])
            bench.record(p, "rays_traced", "rays", [ref.rays_traced])
    main_figures = ["seconds", "samples_per_s", "over_mitsuba"]
    bench.print_table([x for x in bench.recorder.records if x["metric"] in main_figures],
                      rows=("scene", "pixels", "samples", "tracer"), order=main_figures, digits=3)
    print("\nover_mitsuba: Mitsuba's seconds over the tracer's, round by round; the stages of one more reference each "
          "(one value):")
    bench.print_table([x for x in bench.recorder.records if x["metric"] not in main_figures],
                      rows=("scene", "tracer"), digits=0, note=False)


if __name__ == "__main__":
    main()
