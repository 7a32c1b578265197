"""What skipping saves (issue 11): trace + resolve time against the reflective share of the screen.

    python benchmarks/skip.py [--width 320 --height 180 --repeats 7]

A floor of 100 strips seen from above (boxes stand on it to be reflected), a share of the strips
mirrors (roughness 0) or glossy (roughness 0.3), the rest matte without reflectivity. For each
share (0, 1, 10, 50, 100 % of the strips; the share of trace pixels this gives is measured by
Frame.stats and printed) it renders with Settings.skip on (classify + indirect trace over the ray
list) and off (one trace invocation per pixel and ray over the whole image) and prints the median
GPU time of classify + trace + resolve over `repeats` renders after 2 warm-up renders, with the
spread (min-max of the repeats). 0 % keeps one mirror strip off-screen, so the scene still has a
reflective surface and the reflection passes still run. Then, for a view whose depth complexity is
2, depth peeling with 2 and 16 layers allowed (later layers are skipped on the GPU by conditional
rendering): depth_peel, lighting, hiz_build, trace and frame totals, with skip on and off (the
per-layer passes work on the layers used only with skip on). Last, adaptive rays on a floor of
strips of mixed roughness (0 to 0.6): error of the reflection (RMSE over the reflective pixels)
against the converged reference and trace+resolve time, for fixed 8 rays, adaptive rays (at most
8), adaptive rays with the variance-guided second pass, and fixed 2 and 4 rays; also the error
against the same tracer with 32 rays (RMSE/SSR32: the noise alone, without screen space's bias).
The ratios the issue asks for (skip on: 10 % reflective <= 20 % of 100 %, 0 % <= 5 % of 100 %)
are printed after each sweep, for the trace alone and for trace + resolve.

    python benchmarks/skip.py --sections shares peel adaptive
"""

from __future__ import annotations

import statistics

import numpy as np

import ssrlab
from ssrlab.scene import Camera, Environment, Material, Scene, directional_light
from common import benchmark_arguments, open_renderer

STRIPS = 100


def strip_floor(share: float, roughness, boxes: bool = True) -> Scene:
    """`roughness`: one value, or a list the reflective strips cycle through."""
    roughnesses = list(roughness) if isinstance(roughness, (list, tuple)) else [roughness]
    s = Scene()
    s.name = f"strips{share:g}"
    n_reflective = int(round(share * STRIPS))
    mirrors = [Material(base_color=(0.9, 0.9, 0.9), roughness=r, metallic=1.0, reflectivity=1.0) for r in roughnesses]
    mirror = mirrors[0]
    matte = Material(base_color=(0.5, 0.45, 0.4), roughness=0.9, reflectivity=0.0)
    width = 24.0
    for i in range(STRIPS):
        x0 = -width / 2 + i * width / STRIPS
        x1 = x0 + width / STRIPS
        p = np.float32([(x0, 0, 6), (x1, 0, 6), (x1, 0, -30), (x0, 0, -30)])
        s.add_mesh(p, np.array([(0, 1, 2), (0, 2, 3)]), name=f"strip{i}", normals=np.tile(np.float32([0, 1, 0]), (4, 1)),
                   material=mirrors[i % len(mirrors)] if i < n_reflective else matte)
    if n_reflective == 0:  # a reflective surface off-screen: the reflection passes still run
        s.add_plane((0, -50, 60), (1, 1), name="hidden_mirror", material=mirror)
    rng = np.random.default_rng(3)
    for k in range(12 if boxes else 0):
        s.add_box((rng.uniform(-6, 6), 0.6, rng.uniform(-14, -2)), (0.8, 1.2, 0.8), name=f"box{k}",
                  material=Material(base_color=tuple(rng.uniform(0.2, 0.9, 3)), roughness=0.6))
    if not boxes:  # one single-sided plane over the floor instead: depth complexity 2
        s.add_mesh(np.float32([(-6, 1, -2), (2, 1, -2), (2, 1, -10), (-6, 1, -10)]), np.array([(0, 1, 2), (0, 2, 3)]),
                   name="shelf", normals=np.tile(np.float32([0, 1, 0]), (4, 1)), material=matte)
    s.add_light(directional_light((0.3, -1.0, -0.4), intensity=3.0, cast_shadow=False))
    s.environment = Environment.constant((0.2, 0.25, 0.3))
    # Centred on the strips' x-range from its mirrored side, so the lower shares land on screen.
    s.camera = Camera(position=(-3.0, 3.0, 4.0), target=(-3.0, 0.0, -6.0), fov_y=60.0, near=0.1, far=60.0)
    return s


def timed(renderer, scene, settings, keys, repeats):
    for _ in range(2):
        renderer.render(scene, settings=settings)
    frames = [renderer.render(scene, settings=settings) for _ in range(repeats)]
    totals = [sum(f.timings.get(k, 0.0) for k in keys) for f in frames]
    return statistics.median(totals), min(totals), max(totals), frames[-1]


# Trace keys: the first trace, classify before it, and the variance-guided second pass.
def trace_keys(method):
    return ("classify", f"trace_{method}", "variance_rays", f"trace_{method}_extra")


def fmt(m, lo, hi):
    return f"{m:>8.3f} ({lo:.3f}-{hi:.3f})"


def shares_section(r, args):
    for label, roughness, kw in (("mirror, 1 ray", 0.0, dict(sampling="mirror", rays_per_pixel=1)),
                                 ("glossy 0.3, 4 rays", 0.3, dict(sampling="vndf", rays_per_pixel=4))):
        for method in ("linear", "hiz"):
            print(f"{label}, method={method}")
            print(f"  {'share':>6} {'traced px':>9} | {'classify+trace on':>22} {'trace off':>22} | "
                  f"{'+resolve on':>22} {'+resolve off':>22}")
            medians = {}
            for share in args.shares:
                scene = strip_floor(share / 100, roughness)
                trace = trace_keys(method)
                cols = []
                for keys in (trace, trace + ("resolve",)):
                    for skip in (True, False):
                        s = ssrlab.Settings(width=args.width, height=args.height, method=method, skip=skip, **kw)
                        cols.append(timed(r, scene, s, keys, args.repeats))
                medians[share] = [c[0] for c in cols]
                f = cols[0][3]
                px = f.stats.get("pixels_traced", 0) / max(f.stats.get("pixels_classified", 1), 1)
                print(f"  {share:>5g}% {100 * px:>8.1f}% | " + " ".join(
                    fmt(m, lo, hi) + (" |" if i == 1 else "") for i, (m, lo, hi, _) in enumerate(cols)))
            if 100 in medians:
                full = medians[100]
                for share, target in ((10, 20), (0, 5)):
                    if share in medians:
                        part = medians[share]
                        print(f"  {share:g} % / 100 % (issue: <= {target} %), skip on: trace {100 * part[0] / full[0]:.0f} %, "
                              f"trace+resolve {100 * part[2] / full[2]:.0f} %; skip off: trace "
                              f"{100 * part[1] / full[1]:.0f} %, trace+resolve {100 * part[3] / full[3]:.0f} %")
            print()


def peel_section(r, args):
    print("peeling a view of depth complexity 2 (the floor and one plane over it, seen from above), method=hiz")
    scene = strip_floor(0.5, 0.0, boxes=False)
    keys = ("depth_peel", "lighting", "hiz_build", "trace_hiz", "total")
    print(f"  {'layers allowed':>14} {'skip':>5} {'layers_used':>11} " + " ".join(f"{k:>22}" for k in keys))
    for layers, skip in ((2, True), (16, True), (16, False)):
        s = ssrlab.Settings(width=args.width, height=args.height, layers=layers, method="hiz", sampling="mirror",
                            rays_per_pixel=1, skip=skip)
        cols = [timed(r, scene, s, (k,), args.repeats) for k in keys]
        f = cols[0][3]
        print(f"  {layers:>14} {str(skip):>5} {f.stats['layers_used']:>11} " +
              " ".join(fmt(m, lo, hi) for m, lo, hi, _ in cols))
    print()


def adaptive_section(r, args):
    from ssrlab.metrics import rmse

    print("adaptive rays on a floor of strips of roughness 0, 0.1, 0.2, 0.4, 0.6 (all reflective), method=hiz: "
          "reflection RMSE over the reflective pixels against the converged reference "
          f"({args.reference_rays} rays per pixel) and trace+resolve GPU ms")
    scene = strip_floor(1.0, [0.0, 0.1, 0.2, 0.4, 0.6])
    base = dict(width=args.width, height=args.height, method="hiz", sampling="vndf", layers=2, roughness_cutoff=1.0)
    truth = None
    rows = [("fixed 8 rays", dict(rays_per_pixel=8)),
            ("adaptive, max 8", dict(rays_per_pixel=8, adaptive_rays=True)),
            ("adaptive + variance 0.25", dict(rays_per_pixel=8, adaptive_rays=True, variance_rays=True)),
            ("adaptive + variance 0.1", dict(rays_per_pixel=8, adaptive_rays=True, variance_rays=True,
                                             variance_threshold=0.1)),
            ("fixed 4 rays", dict(rays_per_pixel=4)),
            ("fixed 2 rays", dict(rays_per_pixel=2))]
    # The noise alone: the same tracer's image with 32 fixed rays per pixel (its screen-space bias,
    # the same for every row, is left out), as an SSR-converged image.
    ssr_truth = r.render(scene, settings=ssrlab.Settings(**base, rays_per_pixel=32)).reflection
    print(f"  {'rays':>26} {'rays traced':>11} {'extra':>6} {'RMSE':>8} {'RMSE/SSR32':>10} "
          f"{'trace ms':>24} {'trace+resolve ms':>24} {'RMSE x ms':>10}")
    for label, kw in rows:
        s = ssrlab.Settings(**base, **kw)
        mt, lot, hit, _ = timed(r, scene, s, trace_keys("hiz"), args.repeats)
        m, lo, hi, f = timed(r, scene, s, trace_keys("hiz") + ("resolve",), args.repeats)
        if truth is None:
            truth = f.reference(kind="converged", rays=args.reference_rays)
        mask = truth.reflective
        # Error over several seeds: one frame's noise is itself noisy.
        errors, noise = [], []
        for seed in range(args.error_seeds):
            g = r.render(scene, settings=s.replace(seed=seed + 1))
            errors.append(rmse(g.reflection, truth.reflection, mask))
            noise.append(rmse(g.reflection, ssr_truth, mask))
        err, nse = statistics.mean(errors), statistics.mean(noise)
        st = f.stats
        print(f"  {label:>26} {st.get('rays_traced', 0):>11} {st.get('extra_rays', 0):>6} {err:>8.4f} {nse:>10.4f} "
              f"{fmt(mt, lot, hit):>24} {fmt(m, lo, hi):>24} {err * m:>10.3f}")
    print()


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=7)
    ap.set_defaults(width=320, height=180)
    ap.add_argument("--shares", type=float, nargs="+", default=[0, 1, 10, 50, 100])
    ap.add_argument("--sections", nargs="+", default=["shares", "peel", "adaptive"],
                    choices=("shares", "peel", "adaptive"))
    ap.add_argument("--reference-rays", type=int, default=256)
    ap.add_argument("--error-seeds", type=int, default=4)
    args = ap.parse_args()
    r = open_renderer(args)
    print(f"{args.width}x{args.height}, median (min-max) of {args.repeats} runs after 2 warm-up runs; GPU ms\n")
    if "shares" in args.sections:
        shares_section(r, args)
    if "peel" in args.sections:
        peel_section(r, args)
    if "adaptive" in args.sections:
        adaptive_section(r, args)


if __name__ == "__main__":
    main()
