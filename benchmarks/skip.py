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
rendering): depth_peel, lighting and frame totals.
"""

from __future__ import annotations

import statistics

import numpy as np

import ssrlab
from ssrlab.scene import Camera, Environment, Material, Scene, directional_light
from common import benchmark_arguments, open_renderer

STRIPS = 100


def strip_floor(share: float, roughness: float, boxes: bool = True) -> Scene:
    s = Scene()
    s.name = f"strips{share:g}"
    n_reflective = int(round(share * STRIPS))
    mirror = Material(base_color=(0.9, 0.9, 0.9), roughness=roughness, metallic=1.0, reflectivity=1.0)
    matte = Material(base_color=(0.5, 0.45, 0.4), roughness=0.9, reflectivity=0.0)
    width = 24.0
    for i in range(STRIPS):
        x0 = -width / 2 + i * width / STRIPS
        x1 = x0 + width / STRIPS
        p = np.float32([(x0, 0, 6), (x1, 0, 6), (x1, 0, -30), (x0, 0, -30)])
        s.add_mesh(p, np.array([(0, 1, 2), (0, 2, 3)]), name=f"strip{i}", normals=np.tile(np.float32([0, 1, 0]), (4, 1)),
                   material=mirror if i < n_reflective else matte)
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


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=7)
    ap.set_defaults(width=320, height=180)
    ap.add_argument("--shares", type=float, nargs="+", default=[0, 1, 10, 50, 100])
    args = ap.parse_args()
    r = open_renderer(args)
    print(f"{args.width}x{args.height}, median (min-max) of {args.repeats} runs after 2 warm-up runs; GPU ms\n")
    for label, roughness, kw in (("mirror, 1 ray", 0.0, dict(sampling="mirror", rays_per_pixel=1)),
                                 ("glossy 0.3, 4 rays", 0.3, dict(sampling="vndf", rays_per_pixel=4))):
        for method in ("linear", "hiz"):
            print(f"{label}, method={method}")
            print(f"  {'share':>6} {'traced px':>9} | {'classify+trace on':>22} {'trace off':>22} | "
                  f"{'+resolve on':>22} {'+resolve off':>22}")
            for share in args.shares:
                scene = strip_floor(share / 100, roughness)
                trace = ("classify", f"trace_{method}")
                cols = []
                for keys in (trace, trace + ("resolve",)):
                    for skip in (True, False):
                        s = ssrlab.Settings(width=args.width, height=args.height, method=method, skip=skip, **kw)
                        cols.append(timed(r, scene, s, keys, args.repeats))
                f = cols[0][3]
                px = f.stats.get("pixels_traced", 0) / max(f.stats.get("pixels_classified", 1), 1)
                print(f"  {share:>5g}% {100 * px:>8.1f}% | " + " ".join(
                    f"{m:>8.3f} ({lo:.3f}-{hi:.3f})" + (" |" if i == 1 else "") for i, (m, lo, hi, _) in enumerate(cols)))
            print()

    print("peeling a view of depth complexity 2 (the floor and one plane over it, seen from above; skip is on)")
    scene = strip_floor(0.5, 0.0, boxes=False)
    print(f"  {'layers allowed':>14} {'layers_used':>11} {'depth_peel':>22} {'lighting':>22} {'total':>22}")
    for layers in (2, 16):
        s = ssrlab.Settings(width=args.width, height=args.height, layers=layers, sampling="mirror", rays_per_pixel=1)
        cols = [timed(r, scene, s, (k,), args.repeats) for k in ("depth_peel", "lighting", "total")]
        f = cols[0][3]
        print(f"  {layers:>14} {f.stats['layers_used']:>11} " +
              " ".join(f"{m:>8.3f} ({lo:.3f}-{hi:.3f})" for m, lo, hi, _ in cols))


if __name__ == "__main__":
    main()
