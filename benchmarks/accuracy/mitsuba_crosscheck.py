"""The converged reference against Mitsuba 3 on the floor of ssrlab.crosscheck's scene.

Prints PSNR on floor pixels (all of them, and the interior ones without silhouette pixels) of
ssrlab's converged reference against Mitsuba's path tracer. The white metallic floor is rendered
by Mitsuba's own BSDF (crosscheck.own_bsdf: conductor for the mirror, roughconductor with GGX,
visible-normal sampling and alpha = roughness^2 for glossy floors, material "none", whose
Fresnel factor is 1 as ssrlab's Schlick F with F0 = 1 is), and, in a second column, by the
Dr.Jit port of ssrlab's BRDF (bsdf="ssrlab"); the objects are the port in both. For:

* the white mirror floor (F = 1, so the thesis's linear composite and 'pbr' coincide):
  at default settings, then with one cause of disagreement removed at a time, then with the
  exact options (ssrlab.crosscheck.exact_options) — the table diagnoses where they differ; and
  a frame of a sequence after objects moved (ssrlab.crosscheck.MOVES), at default settings;
* a tinted Schlick mirror (F0 = copper-like base colour, composite 'pbr'; Mitsuba has no Schlick
  Fresnel, so the port renders this floor);
* glossy floors (--roughness, default 0.2 and 0.5; composite 'pbr', and the thesis's linear
  composite): two Mitsuba renders and two ssrlab references with different seeds split the
  difference into Monte-Carlo noise and bias (crosscheck.noise_agreement): the mean floor
  radiance ratio ssrlab / Mitsuba (± its standard error) and the mean and the per-pixel squared
  bias in standard errors (z), for Mitsuba's roughconductor and for the port;
* the frames themselves on the mirror floor at each of --frame-sizes (default settings): SSR
  alone, SSR + the BVH fallback (fallback="bvh": traced shadows by default, and
  bvh_shadows="map") and pure BVH (method="bvh", both shadows), each frame's image against
  Mitsuba and against ssrlab's converged physical reference (shadows="traced", viewer="ray"),
  with the frame's GPU time (--repeats rounds after the protocol's warm-up rounds, the frames
  interleaved round by round).

Every figure is a record (ssrlab.lab.records): the PSNRs and noise statistics one value each (the
renders are deterministic for their seeds), the frames' GPU times with their samples; the
tables are rendered from the records and the verdicts printed from the same figures.

    python benchmarks/accuracy/mitsuba_crosscheck.py                 # 640x360, about 12 minutes on llvmpipe
    python benchmarks/accuracy/mitsuba_crosscheck.py --width 160 --height 90 --spp 64
    python benchmarks/accuracy/mitsuba_crosscheck.py --only-frames --frame-sizes 320x180,640x360
"""

from __future__ import annotations

import sys
from pathlib import Path
import time

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import HYBRID_FRAMES, benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402

import ssrlab  # noqa: E402
from ssrlab import crosscheck as cc  # noqa: E402

SHARP_SHADOWS = dict(shadow_map_size=8192, shadow_pcf_radius=0, shadow_normal_offset=0.5)
TINY_BIAS = dict(origin_bias=1e-5)


def mse(a, b, m):
    return float(np.mean((a[m] - b[m]) ** 2))


# Goals at default settings (dB on interior floor pixels) and against what: SSR + BVH fallback
# against both Mitsuba and the physical reference, pure BVH against Mitsuba.
FRAME_GOALS = {"SSR + BVH fallback": (40.0, True), "pure BVH": (45.0, False)}
# Mitsuba's own BSDF on the floor: the mirror (conductor) to this PSNR (dB, default settings, interior
# floor pixels whose reflection lands on no silhouette), glossy floors (roughconductor) to the noise:
# mean and per-pixel squared bias within NOISE_Z standard errors (tests/test_mitsuba.py's bound).
MIRROR_GOAL, NOISE_Z = 45.0, 4.0


def frames_table(bench, renderer, sizes) -> None:
    """Each frame's image on the mirror floor against Mitsuba and the converged physical reference,
    and its GPU time (the frames interleaved round by round)."""
    scene = cc.crosscheck_scene(0.0)
    verdicts = []
    recs = []
    for W, H in sizes:
        ms = cc.mitsuba_scene(scene, width=W, height=H)
        mit = cc.render_mitsuba(ms, spp=1)
        base = ssrlab.Settings(width=W, height=H)
        frame, truth = cc.ssrlab_reference(renderer, scene, base)
        physical = truth.color.copy()
        raw, inner = cc.floor_pixels(frame, interior=False), cc.floor_pixels(frame)
        smooth = inner & ~cc.reflected_silhouettes(ms)
        configs = {name: base.replace(**kw) for name, kw in HYBRID_FRAMES.items()}
        times = bench.frames(renderer, scene, configs)
        for name, st in configs.items():
            c = renderer.render(scene, settings=st).color.copy()
            params = dict(section="frames", frame=name, width=W, height=H)
            row = {"vs_mitsuba_floor": cc.floor_psnr(c, mit, raw), "vs_mitsuba_interior": cc.floor_psnr(c, mit, inner),
                   "vs_mitsuba_smooth": cc.floor_psnr(c, mit, smooth),
                   "vs_physical_interior": cc.floor_psnr(c, physical, inner)}
            recs += [bench.record(params, k, "dB", [v], better="higher") for k, v in row.items()]
            recs.append(bench.record(params, "frame", "ms", times[name]["total"]))
            if name in FRAME_GOALS:
                goal, also_physical = FRAME_GOALS[name]
                value = min(row["vs_mitsuba_interior"], row["vs_physical_interior"]) if also_physical \
                    else row["vs_mitsuba_interior"]
                target = "Mitsuba and the physical reference" if also_physical else "Mitsuba"
                verdicts.append(f"{name} {W}x{H}: {value:.2f} dB against {target} (interior floor pixels); "
                                f"goal >= {goal:.0f} dB: {'met' if value >= goal else 'not met'}")
    print(f"\nframes on the mirror floor (default settings, traced shadows in the BVH passes, but for the row's): "
          f"final image's PSNR against Mitsuba (all floor pixels, interior, smooth) and against ssrlab's converged "
          f"physical reference (interior); frame GPU ms of {bench.repeats} rounds after {bench.warmup} warm-up rounds")
    bench.print_table(recs, rows=("width", "height", "frame"), digits=2)
    print("\n" + "\n".join(verdicts))


def main() -> None:
    ap = benchmark_arguments(__doc__)
    ap.add_argument("--spp", type=int, default=256, help="samples per pixel on glossy floors (both renderers)")
    ap.add_argument("--roughness", type=float, nargs="+", default=[0.2, 0.5])
    ap.add_argument("--frame-sizes", default="320x180,640x360",
                    help="comma-separated WxH list of the frames' table (empty: none)")
    ap.add_argument("--only-frames", action="store_true", help="print the frames' table only")
    ap.add_argument("--repeats", type=int, default=5, help="timed renders per frame of the frames' table")
    args = ap.parse_args()
    renderer = open_renderer(args)
    bench = Bench("mitsuba_crosscheck", args, renderer)
    cc.load_mitsuba()
    print(cc.mitsuba_version())
    sizes = [tuple(int(x) for x in s.lower().split("x")) for s in args.frame_sizes.split(",") if s]
    if args.only_frames:
        frames_table(bench, renderer, sizes)
        return
    W, H = args.width, args.height
    base = ssrlab.Settings(width=W, height=H)
    exact, exact_kw, used = cc.exact_options(base)
    print(f"{W}x{H}; exact options available: {', '.join(used)}; robust reference offset: "
          f"{cc.reference_ignores_origin_bias(renderer)}")

    # -- mirror floor ---------------------------------------------------------------------
    verdicts = []
    scene = cc.crosscheck_scene(0.0)
    ms = cc.mitsuba_scene(scene, width=W, height=H, bsdf="mitsuba")
    t = time.perf_counter()
    mit = cc.render_mitsuba(ms, spp=1)  # pixel-centre rays, delta floor: one path is exact
    t_mit = time.perf_counter() - t
    mit_port = cc.render_mitsuba(cc.mitsuba_scene(scene, width=W, height=H, bsdf="ssrlab"), spp=1)
    frame0, _ = cc.ssrlab_reference(renderer, scene, base)
    agree = float((np.where(frame0.gbuffer.coverage[0], frame0.gbuffer.object_id[0], -1)
                   == cc.first_hit_objects(ms)).mean())
    print(f"\nmirror floor (white, F = 1): Mitsuba {t_mit:.1f} s; floor: Mitsuba's {ms.own_bsdf.get(cc.FLOOR)}; "
          f"camera rays hit the same object in {100 * agree:.2f} % of pixels; Mitsuba's conductor and the port "
          f"differ by at most {np.abs(mit - mit_port).max():.2e}")
    # Default settings first (exact origins, traced shadows, the physical viewer), then the
    # reference's options that trade exactness for agreement with what SSR sees.
    rows = [
        ("default settings", base, {}),
        ("origin_bias 0.05 (no effect: exact origins)", base.replace(origin_bias=0.05), {}),
        ("viewer='camera' (the lit G-buffer's view)", base, {"viewer": "camera"}),
        ("shadows='map' (the frame's shadow map)", base, {"shadows": "map"}),
        ("shadows='map', sharp shadow map", base.replace(**SHARP_SHADOWS), {"shadows": "map"}),
        ("viewer='camera', shadows='map' (SSR's view)", base, {"viewer": "camera", "shadows": "map"}),
        ("composite='pbr'", base.replace(composite="pbr"), {}),
    ]
    edges = cc.reflected_silhouettes(ms)
    print("PSNR against Mitsuba's conductor over all floor pixels, interior ones (no silhouette in the image) and\n"
          "interior ones whose reflection lands on no silhouette (reflected silhouettes: where Mitsuba's larger ray\n"
          "offset flips hits); smooth_vs_port: smooth ones against the port of ssrlab's BRDF on the floor")
    size = dict(width=W, height=H)

    def psnrs(section, reference, c, target, raw, inner, smooth, port=None, **extra):
        params = dict(section=section, reference=reference, **size, **extra)
        out = [bench.record(params, "floor", "dB", [cc.floor_psnr(c, target, raw)], better="higher"),
               bench.record(params, "interior", "dB", [cc.floor_psnr(c, target, inner)], better="higher"),
               bench.record(params, "smooth", "dB", [cc.floor_psnr(c, target, smooth)], better="higher"),
               bench.record(params, "mse_smooth", "", [mse(c, target, smooth)])]
        if port is not None:
            out.append(bench.record(params, "smooth_vs_port", "dB", [cc.floor_psnr(c, port, smooth)], better="higher"))
        return out

    mirror = []
    for name, s, kw in rows:
        frame, truth = cc.ssrlab_reference(renderer, scene, s, **kw)
        raw, inner = cc.floor_pixels(frame, interior=False), cc.floor_pixels(frame)
        smooth = inner & ~edges
        c = truth.color
        mirror += psnrs("mirror floor", name, c, mit, raw, inner, smooth, mit_port)
        if name == "default settings":
            value = cc.floor_psnr(c, mit, smooth)
            verdicts.append(f"mirror floor {W}x{H}, Mitsuba's conductor: {value:.2f} dB at default settings (smooth "
                            f"floor pixels; interior {cc.floor_psnr(c, mit, inner):.2f} dB); goal >= "
                            f"{MIRROR_GOAL:.0f} dB: {'met' if value >= MIRROR_GOAL else 'not met'}")
    pixels = f"({raw.sum()} floor pixels, {inner.sum()} interior, {smooth.sum()} smooth)"

    # -- a frame after objects moved: the sequence's second frame, crosscheck.MOVES applied ------
    moved_scene = cc.crosscheck_scene(0.0)
    frame, truth = cc.moved_reference(renderer, moved_scene, base)
    mms = cc.mitsuba_scene(moved_scene, width=W, height=H)
    mmit = cc.render_mitsuba(mms, spp=1)
    inner = cc.floor_pixels(frame)
    smooth = inner & ~cc.reflected_silhouettes(mms)
    agree = float((np.where(frame.gbuffer.coverage[0], frame.gbuffer.object_id[0], -1) == cc.first_hit_objects(mms)).mean())
    mirror += psnrs("mirror floor", "moved frame (crosscheck.MOVES), default settings", truth.color, mmit,
                    cc.floor_pixels(frame, interior=False), inner, smooth)
    bench.print_table(mirror, rows=("reference",), digits=2)
    print(f"{pixels}; the moved frame's camera rays hit the same object in {100 * agree:.2f} % of pixels")

    # -- tinted Schlick mirror --------------------------------------------------------------
    tint = (0.95, 0.64, 0.54)
    scene = cc.crosscheck_scene(0.0, floor_color=tint)
    ms = cc.mitsuba_scene(scene, width=W, height=H)
    mit = cc.render_mitsuba(ms, spp=1)
    edges = cc.reflected_silhouettes(ms)
    print(f"\ntinted mirror (F0 = {tint}, Schlick), composite='pbr' (the port on the floor: Mitsuba's BSDFs have no "
          f"Schlick Fresnel):")
    tinted = []
    for name, s, kw in [("composite='pbr'", base.replace(composite="pbr"), {}),
                        ("pbr, exact options, origin_bias 1e-5", exact.replace(composite="pbr", **TINY_BIAS),
                         exact_kw)]:
        frame, truth = cc.ssrlab_reference(renderer, scene, s, **kw)
        raw, inner = cc.floor_pixels(frame, interior=False), cc.floor_pixels(frame)
        tinted.extend(psnrs("tinted mirror", name, truth.color, mit, raw, inner, inner & ~edges))
    bench.print_table(tinted, rows=("reference",), digits=2)

    # -- glossy floors -----------------------------------------------------------------------
    for rough in args.roughness:
        scene = cc.crosscheck_scene(rough)
        mits, seconds = {}, {}
        for bsdf in cc.BSDFS:
            ms = cc.mitsuba_scene(scene, width=W, height=H, bsdf=bsdf)
            t = time.perf_counter()
            mits[bsdf] = (cc.render_mitsuba(ms, spp=args.spp, seed=1), cc.render_mitsuba(ms, spp=args.spp, seed=2))
            seconds[bsdf] = (time.perf_counter() - t) / 2
            if bsdf == "mitsuba":
                own = ms.own_bsdf.get(cc.FLOOR, "the port")
        label = {"mitsuba": f"Mitsuba's {own}", "ssrlab": "port"}
        same_seed = float(np.abs(mits["mitsuba"][0] - mits["ssrlab"][0]).max())
        print(f"\nglossy floor, roughness {rough} (white metal), {args.spp} samples per pixel each (Mitsuba "
              f"{seconds['mitsuba']:.1f} s per image with its {own}, {seconds['ssrlab']:.1f} s with the port, one "
              f"render each; with the same seed the two differ by at most {same_seed:.2e}); noise from two seeds of "
              f"each; z: standard errors")
        glossy = []
        for name, s, kw in [("composite='pbr'", base.replace(composite="pbr"), {}),
                            ("pbr, exact options, origin_bias 1e-5",
                             exact.replace(composite="pbr", **TINY_BIAS), exact_kw),
                            ("linear (default), exact options", exact.replace(**TINY_BIAS), exact_kw)]:
            fa, ta = cc.ssrlab_reference(renderer, scene, s, rays=args.spp, seed=0, **kw)
            a = ta.color.copy()
            _, tb = cc.ssrlab_reference(renderer, scene, s, rays=args.spp, seed=1, **kw)
            b = tb.color.copy()
            inner = cc.floor_pixels(fa)
            for bsdf in cc.BSDFS:
                m1, m2 = mits[bsdf]
                na = cc.noise_agreement(a, b, m1, m2, inner)
                bias_db = 10 * np.log10(1.0 / na["bias2"]) if na["bias2"] > 0 else float("inf")
                psnr = cc.floor_psnr(a, m1, inner)
                params = dict(section="glossy floor", roughness=rough, reference=name, floor_bsdf=label[bsdf],
                              spp=args.spp, **size)
                for metric, unit, v in (("psnr", "dB", psnr), ("mitsuba_vs_mitsuba", "dB", cc.floor_psnr(m1, m2, inner)),
                                        ("ssrlab_vs_ssrlab", "dB", cc.floor_psnr(a, b, inner)),
                                        ("mse_over_noise", "", na["mse_over_noise"]), ("bias_psnr", "dB", bias_db),
                                        ("mean_ssrlab_over_mitsuba", "x", 1 + na["mean_relative"]),
                                        ("se_mean", "x", na["se_mean_relative"]), ("z_mean", "z", na["z_mean"]),
                                        ("z_bias2", "z", na["z_bias2"])):
                    glossy.append(bench.record(params, metric, unit, [v]))
                if bsdf == "mitsuba" and name == "composite='pbr'":
                    ok = abs(na["z_mean"]) <= NOISE_Z and na["z_bias2"] <= NOISE_Z
                    verdicts.append(f"glossy floor {rough} {W}x{H}, {label[bsdf]}: {psnr:.2f} dB "
                                    f"(Mitsuba's two seeds {cc.floor_psnr(m1, m2, inner):.2f} dB), mean "
                                    f"{1 + na['mean_relative']:.4f} ± {na['se_mean_relative']:.4f}, z mean "
                                    f"{na['z_mean']:.2f}, z bias2 {na['z_bias2']:.2f}; goal: both within "
                                    f"{NOISE_Z:.0f} standard errors: {'met' if ok else 'not met'}")
        bench.print_table(glossy, rows=("reference", "floor_bsdf"), digits=3, note=False)
    print("\n" + "\n".join(verdicts))

    # -- the frames: SSR, the hybrid and pure BVH -----------------------------------------------
    if sizes:
        frames_table(bench, renderer, sizes)


if __name__ == "__main__":
    main()
