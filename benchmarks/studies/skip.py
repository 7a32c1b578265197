"""What skipping saves: trace + resolve time against the reflective share of the screen.

    python benchmarks/studies/skip.py [--width W --height H] [--repeats 7] [--sections shares peel adaptive]

A floor of 100 strips seen from above (boxes stand on it to be reflected), some strips mirrors
(roughness 0) or glossy (roughness 0.3), the rest matte without reflectivity. For each share of the
screen (0, 1, 10, 50 %: the strips whose pixels, counted from the G-buffer's object ids, make that
share; 100 %: every strip, which covers the floor's part of the screen; the measured reflective
share of the screen is printed) it renders with Settings.skip on (classify + indirect trace over the ray
list) and off (one trace invocation per pixel and ray over the whole image) and prints the median
GPU time of classify + trace + resolve over `repeats` renders after 2 warm-up renders, with the
spread (min-max of the repeats). 0 % keeps one mirror strip off-screen, so the scene still has a
reflective surface and the reflection passes still run. Then, for a view whose depth complexity is
2, depth peeling with 2 and 16 layers allowed (later layers are skipped on the GPU by conditional
rendering): depth_peel, lighting, hiz_build, trace and frame totals, with skip on and off (the
per-layer passes work on the layers used only with skip on). Last, adaptive rays' error per time
(gallery(): a floor of strips of mixed roughness before a checkered wall in view, so that screen
space's misses stay few and the BVH tracer's error against the converged reference is its noise
alone): for method "bvh" and "hiz", with and without the resolve's 3x3 reuse, fixed 1-16 rays
against adaptive rays (at most 8, 16; with variance-guided rays for Hi-Z), each row over several
seeds: RMSE against the converged reference, trace and trace+resolve time, MSE x ms, RMSE per
roughness class, verdicts at equal time (only where the spreads do not overlap), the best
roughness -> rays map the fixed rows' per-class errors allow, and a paired bias check of the
adaptive and fixed frames' means.
The ratios the issue asks for (skip on: 10 % reflective <= 20 % of 100 %, 0 % <= 5 % of 100 %)
are printed after each sweep, for the trace alone and for trace + resolve.

    python benchmarks/studies/skip.py --sections shares peel adaptive

Every timed figure is a record (ssrlab.lab.records) with its samples.
"""

from __future__ import annotations

import sys
from pathlib import Path
import argparse
import statistics

import numpy as np

import ssrlab
from ssrlab.scene import Camera, Environment, Material, Scene, directional_light
from ssrlab.scenes import GALLERY_ROUGHNESS, gallery

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab import records  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402

STRIPS = 100


def strip_floor(share: float, roughness, boxes: bool = True, reflective=None) -> Scene:
    """`roughness`: one value, or a list the reflective strips cycle through. `reflective`: the
    indices of the reflective strips (default: the first `share` of them)."""
    roughnesses = list(roughness) if isinstance(roughness, (list, tuple)) else [roughness]
    s = Scene()
    s.name = f"strips{share:g}"
    chosen = set(range(int(round(share * STRIPS)))) if reflective is None else set(reflective)
    n_reflective = len(chosen)
    mirrors = [Material(base_color=(0.9, 0.9, 0.9), roughness=r, metallic=1.0, reflectivity=1.0) for r in roughnesses]
    mirror = mirrors[0]
    matte = Material(base_color=(0.5, 0.45, 0.4), roughness=0.9, reflectivity=0.0)
    width = 64.0  # wide enough to fill the view's sides
    for i in range(STRIPS):
        x0 = -width / 2 + i * width / STRIPS
        x1 = x0 + width / STRIPS
        p = np.float32([(x0, 0, 6), (x1, 0, 6), (x1, 0, -30), (x0, 0, -30)])
        s.add_mesh(p, np.array([(0, 1, 2), (0, 2, 3)]), name=f"strip{i}", normals=np.tile(np.float32([0, 1, 0]), (4, 1)),
                   material=mirrors[i % len(mirrors)] if i in chosen else matte)
    if n_reflective == 0:  # a reflective surface off-screen: the reflection passes still run
        s.add_plane((0, -50, 60), (1, 1), name="hidden_mirror", material=mirror)
    rng = np.random.default_rng(3)
    for k in range(12 if boxes else 0):
        box = Material(base_color=tuple(rng.uniform(0.2, 0.9, 3)), roughness=0.6)
        # Every strip reflective: the boxes too, so that the whole screen reflects (100 %).
        s.add_box((rng.uniform(-6, 6), 0.6, rng.uniform(-14, -2)), (0.8, 1.2, 0.8), name=f"box{k}",
                  material=mirrors[k % len(mirrors)] if n_reflective == STRIPS else box)
    if not boxes:  # one single-sided plane over the floor instead: depth complexity 2
        s.add_mesh(np.float32([(-6, 1, -2), (2, 1, -2), (2, 1, -10), (-6, 1, -10)]), np.array([(0, 1, 2), (0, 2, 3)]),
                   name="shelf", normals=np.tile(np.float32([0, 1, 0]), (4, 1)), material=matte)
    s.add_light(directional_light((0.3, -1.0, -0.4), intensity=3.0, cast_shadow=False))
    s.environment = Environment.constant((0.2, 0.25, 0.3))
    # Looking down at the floor steeply enough that it fills the view (its far edge, z = -30,
    # lies beyond the top of the image), so that a share of the strips can be any share of the screen.
    s.camera = Camera(position=(0.0, 3.0, 4.0), target=(0.0, 0.0, 0.0), fov_y=60.0, near=0.1, far=60.0)
    return s


BENCH = None  # the run's Bench (ssrlab.lab.protocol), made by main()


def timed(renderer, scene, settings, keys, repeats, params=None):
    """(median, min, max, last frame, samples) of the summed GPU ms of `keys` over the protocol's rounds
    after 2 warm-ups; recorded as a figure of `params` (the scene, settings and keys)."""
    last = {}
    t = BENCH.frames(renderer, scene, {"x": settings}, repeats=repeats, keep=lambda _, f: last.update(f=f))["x"]
    totals = [sum(t[k][i] for k in keys if k in t) for i in range(len(t["total"]))]
    BENCH.record({**(params or {"scene": scene.name}), "method": settings.method, "skip": settings.skip,
                  "layers": settings.layers, "rays_per_pixel": settings.rays_per_pixel, "width": settings.width,
                  "height": settings.height}, "+".join(keys), "ms", totals)
    return statistics.median(totals), min(totals), max(totals), last["f"], totals


# Trace keys: the first trace, classify before it, and the variance-guided second pass.
def trace_keys(method):
    return ("classify", f"trace_{method}", "variance_rays", f"trace_{method}_extra")


def screen_share_strips(r, args, share: float) -> list[int]:
    """The strips whose pixels make `share` of the screen (varying "the reflective share
    of the screen"): each strip's pixels measured once from the G-buffer's object ids, then the
    strips that still fit, every other one first, so the measured share lands within half a strip
    of the target.
    share 1: every strip (the floor does not fill the whole screen: the share is printed)."""
    if share >= 1.0:
        return list(range(STRIPS))
    f = r.render(strip_floor(1.0, 0.0), settings=ssrlab.Settings(width=args.width, height=args.height))
    ids = f.gbuffer.object_id[0]
    counts = np.bincount(ids[(ids >= 0) & (ids < STRIPS)].ravel(), minlength=STRIPS)
    goal, total, chosen = share * ids.size, 0, []
    # Every other strip first (the reflective pixels spread over the view, not in one block),
    # then the rest, each while it fits within half its own size of the goal.
    for i in list(range(0, STRIPS, 2)) + list(range(1, STRIPS, 2)):
        if counts[i] > 0 and total + counts[i] <= goal + counts[i] / 2:
            chosen.append(i)
            total += int(counts[i])
    return chosen


def shares_section(r, args):
    for label, roughness, kw in (("mirror, 1 ray", 0.0, dict(sampling="mirror", rays_per_pixel=1)),
                                 ("glossy 0.3, 4 rays", 0.3, dict(sampling="vndf", rays_per_pixel=4))):
        for method in ("linear", "hiz"):
            print(f"{label}, method={method}")
            medians, table = {}, []
            for share in args.shares:
                scene = strip_floor(share / 100, roughness, reflective=screen_share_strips(r, args, share / 100))
                trace = trace_keys(method)
                cols = []
                for keys in (trace, trace + ("resolve",)):
                    for skip in (True, False):
                        s = ssrlab.Settings(width=args.width, height=args.height, method=method, skip=skip, **kw)
                        cols.append(timed(r, scene, s, keys, args.repeats,
                                          dict(section="shares", share=share, surface=label)))
                medians[share] = [c[0] for c in cols]
                f = cols[0][3]
                px = float((f.gbuffer.reflectivity[0] > 0).mean())  # the measured reflective share of the screen
                table.append([f"{share:g} %", f"{100 * px:.1f} %", *(records.cell(c[4], 3) for c in cols)])
            print(records.markdown(["share", "screen", "classify+trace, skip on", "trace, skip off",
                                    "+resolve, skip on", "+resolve, skip off"], table))
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
    table = []
    for layers, skip in ((2, True), (16, True), (16, False)):
        s = ssrlab.Settings(width=args.width, height=args.height, layers=layers, method="hiz", sampling="mirror",
                            rays_per_pixel=1, skip=skip)
        cols = [timed(r, scene, s, (k,), args.repeats, dict(section="peel", layers_allowed=layers)) for k in keys]
        f = cols[0][3]
        table.append([layers, skip, f.stats["layers_used"], *(records.cell(c[4], 3) for c in cols)])
    print(records.markdown(["layers allowed", "skip", "layers_used", *keys], table))
    print()


# The floor's roughness mixes (the strips cycle through them): "graded", every step from mirror
# to 0.6; "mirrors", two mirror strips for one of roughness 0.5 (a polished floor among glossy
# ones: most reflective pixels need one ray).
ADAPTIVE_MIXES = {"graded": GALLERY_ROUGHNESS, "mirrors": (0.0, 0.0, 0.5)}


def adaptive_rows(method: str):
    """(label, Settings keywords, fixed ray count or None) of the adaptive section."""
    rows = [(f"fixed {n}", dict(rays_per_pixel=n), n) for n in (1, 2, 4, 8, 16)]
    rows += [("adaptive <= 8", dict(rays_per_pixel=8, adaptive_rays=True), None),
             ("adaptive <= 16", dict(rays_per_pixel=16, adaptive_rays=True), None)]
    if method == "bvh":  # what the compacted list gives: the same rays, one invocation per ray slot
        rows.append(("adaptive <= 8, skip off", dict(rays_per_pixel=8, adaptive_rays=True, skip=False), None))
    else:  # variance_rays: the screen-space tracers only
        rows += [("adaptive <= 8 + variance", dict(rays_per_pixel=8, adaptive_rays=True, variance_rays=True), None),
                 ("adaptive <= 16 + variance", dict(rays_per_pixel=16, adaptive_rays=True, variance_rays=True), None)]
    return rows


def fixed_error_at(fixed, t):
    """The fixed-count rows' error at time `t`, interpolated in log-log between the two rows
    around it ((ms, error) pairs sorted by time); None outside their range (no extrapolation)."""
    for (t0, e0), (t1, e1) in zip(fixed, fixed[1:]):
        if t0 <= t <= t1 and t1 > t0:
            f = (np.log(t) - np.log(t0)) / (np.log(t1) - np.log(t0))
            return float(np.exp(np.log(e0) + f * (np.log(e1) - np.log(e0))))
    return None


def adaptive_section(r, args):
    """Adaptive rays' error per time against fixed ray counts, on gallery(): per method, every row
    rendered with seeds 1..n, each frame timed and its error measured."""
    for wall in args.adaptive_walls:
        for mix in args.adaptive_mixes:
            adaptive_scene(r, args, wall, ADAPTIVE_MIXES[mix])


def adaptive_scene(r, args, wall, roughness):
    from ssrlab.metrics import rmse

    scene = gallery(roughness, wall=wall)
    values = sorted(set(roughness))  # the roughness classes
    n = max(args.repeats, args.error_seeds)
    print(f"adaptive rays on a mixed-roughness floor (strips of roughness {', '.join(map(str, roughness))}, "
          f"cycled) in front of a {wall} wall in view; {n} frames per row (seeds 1..{n}) in two rounds over the rows")
    truth = None
    for method, reuse in [(m, k) for m in args.adaptive_methods for k in args.adaptive_reuse]:
        # reuse_radius 1 (the default: each pixel also averages its 3x3 neighbours' rays, BRDF-
        # weighted, so a rough pixel already gathers many rays) and 0 (each pixel its own rays).
        base = dict(width=args.width, height=args.height, method=method, sampling="vndf", layers=1,
                    roughness_cutoff=1.0, reuse_radius=reuse)
        rows = adaptive_rows(method)
        trace = ("trace_bvh",) if method == "bvh" else trace_keys(method)
        settings = [ssrlab.Settings(**base, **kw) for _, kw, _ in rows]
        f = None
        for s in settings:  # warm-up: shader variants
            f = r.render(scene, settings=s)
        if truth is None:
            # The converged reference as the lit G-buffer sees the hit surfaces (viewer "camera",
            # the frame's shadow map: what the BVH tracer shades), so the BVH tracer's error is
            # its noise alone. Two references of different seeds: their mean is the truth and
            # their difference measures what noise the truth itself keeps.
            refs = []
            for k in (1, 2):  # read each before the next overwrites the frame's reference textures
                ref = f.reference(kind="converged", rays=args.reference_rays, seed=k, viewer="camera", shadows="map")
                refs.append((np.array(ref.reflection), np.array(ref.reflective)))
            mask = refs[0][1]
            truth = 0.5 * (refs[0][0] + refs[1][0])
            truth_mse = rmse(refs[0][0], refs[1][0], mask) ** 2 / 4
            print(f"  converged reference: mean of 2 x {args.reference_rays} rays per pixel, its own noise "
                  f"RMSE {np.sqrt(truth_mse):.5f} (subtracted from the MSE below); {int(mask.sum())} reflective px")
        times = {label: ([], []) for label, _, _ in rows}
        errors = {label: [] for label, _, _ in rows}
        images = {label: [] for label, _, _ in rows}
        rays = {}
        # classes: per roughness of the floor, its pixels among the reflective ones
        class_rays = {}  # per row, the rays drawn in each class
        # Two rounds over the rows, each a block of frames of one row after one warm-up frame
        # (a block reuses its textures; a row switch reallocates them), so that the machine's
        # load drifts over every row alike.
        blocks = [range(1, n // 2 + 1), range(n // 2 + 1, n + 1)]
        block_of = {"round": -1}

        def run_block(label, s, first):
            def run():
                if first:
                    block_of["round"] += 1
                r.render(scene, settings=s)  # the block's warm-up frame
                for seed in blocks[block_of["round"]]:
                    f = r.render(scene, settings=s.replace(seed=seed))
                    times[label][0].append(sum(f.timings.get(k, 0.0) for k in trace))
                    times[label][1].append(sum(f.timings.get(k, 0.0) for k in trace + ("resolve",)))
                    img = f.reflection
                    errors[label].append(rmse(img, truth, mask))
                    images[label].append(img[mask])
                    if seed == 1:  # the rays drawn (weight > 0): method "bvh" has no trace counter
                        drawn = (f.read("rays.sample")[..., 0] > 0).sum(axis=0)
                        rays[label] = int(drawn.sum())
                        if not classes:
                            rough = f.gbuffer.roughness[0]
                            classes.extend(np.abs(rough[mask] - v) < 0.02 for v in values)
                        class_rays[label] = [int(drawn[mask][c].sum()) for c in classes]
                return {}
            return run

        classes = []
        # the protocol's rounds, one block each (every frame of a block recorded)
        BENCH.rounds({label: run_block(label, s, i == 0) for i, ((label, _, _), s) in enumerate(zip(rows, settings))},
                     repeats=len(blocks), warmup=0)
        print(f"method={method}, reuse_radius={reuse}, {args.width}x{args.height}, 1 layer; "
              f"GPU ms median [25th-75th percentile] of {n} frames; "
              "RMSE of the reflection over the reflective pixels, mean (min-max) of the frames; "
              "MSE x ms: (MSE - the reference's) x trace+resolve ms, the inverse of Monte Carlo efficiency, "
              "constant over ray counts for an unbiased estimator whose time follows its rays")
        summary, table = {}, []
        for label, _, count in rows:
            e = errors[label]
            mt, mtr = statistics.median(times[label][0]), statistics.median(times[label][1])
            mse = max(statistics.mean(x * x for x in e) - truth_mse, 0.0)
            summary[label] = (count, times[label], e)
            params = dict(section="adaptive", wall=wall, roughness=list(roughness), method=method,
                          reuse_radius=reuse, rays=label, width=args.width, height=args.height)
            BENCH.record(params, "+".join(trace), "ms", times[label][0])
            BENCH.record(params, "+".join(trace + ("resolve",)), "ms", times[label][1])
            BENCH.record(params, "rmse", "", e)
            table.append([label, rays[label], f"{statistics.mean(e):.5f} ({min(e):.5f}-{max(e):.5f})",
                          records.cell(times[label][0], 3), records.cell(times[label][1], 3), f"{1e3 * mse * mtr:.4f}",
                          f"{1e6 * mt / max(rays[label], 1):.0f}"]
                         + [f"{np.sqrt(np.mean([np.mean((im[c] - truth[mask][c]) ** 2) for im in images[label]])):.4f}"
                            for c in classes])
        print(records.markdown(["rays", "rays traced", "RMSE mean (min-max)", "trace ms", "trace+resolve ms",
                                "MSE x ms", "ns/ray", *(f"RMSE at roughness {v}" for v in values)], table))
        adaptive_verdicts(summary, n)
        best_allocation(rows, images, truth[mask], classes, values, rays, class_rays)
        # Unbiased? The n-frame means of adaptive and fixed rays differ by their noise alone if
        # the resolve's weights keep adaptive rays unbiased. A seed's adaptive rays are the first
        # rays of the same seed's fixed frame, so the two frames' noise is correlated: the test
        # is paired, on the per-frame difference d = adaptive - fixed. Its mean's square over
        # its variance / n, per pixel, averages ~1 if the two have the same expectation.
        for fixed, adaptive in (("fixed 8", "adaptive <= 8"), ("fixed 16", "adaptive <= 16")):
            a, b = np.stack(images[adaptive]), np.stack(images[fixed])
            d = a - b
            diff = np.mean(d.mean(0) ** 2)
            expected = np.mean(d.var(0, ddof=1) / n)
            ea = float(np.sqrt(np.mean((a.mean(0) - truth[mask]) ** 2)))
            eb = float(np.sqrt(np.mean((b.mean(0) - truth[mask]) ** 2)))
            ratio = diff / expected
            verdict = ("agree within their noise (unbiased)" if ratio < 1.25 else
                       "differ beyond their noise: adaptive rays are biased here" if ratio > 2.0 else "undecided")
            print(f"  bias check, mean of {n} frames: {adaptive} RMSE {ea:.5f}, {fixed} {eb:.5f}; "
                  f"mean squared difference of the means / its expectation from noise = {ratio:.2f}: {verdict}")
        print()


def best_allocation(rows, images, truth, classes, values, rays, class_rays):
    """What a roughness -> rays rule could give at best, in rays (not time): from the fixed rows'
    error per roughness class, the map (one of the fixed counts per class) with the lowest error
    for each adaptive row's rays, against the fixed rows' error at those rays (log-log). An
    emulation: it composes the classes of different frames (a strip's edge reuses its
    neighbour strip's rays at that strip's own count)."""
    import itertools

    counts = [c for _, _, c in rows if c is not None]
    share = np.array([c.mean() for c in classes])
    mse = {c: np.array([np.mean([np.mean((im[k] - truth[k]) ** 2) for im in images[f"fixed {c}"]]) for k in classes])
           for c in counts}
    px = sum(c.sum() for c in classes)
    fixed_curve = sorted((rays[f"fixed {c}"], float(np.sqrt(share @ mse[c]))) for c in counts)
    for label, kw, c in rows:
        if c is not None or kw.get("variance_rays") or kw.get("skip") is False:
            continue
        budget = rays[label] / px  # rays per reflective pixel
        best = None
        for combo in itertools.product(counts, repeat=len(classes)):
            # The rays this map draws: each class's rays as the fixed row of its count drew them
            # (a few VNDF samples come out invalid, more on rough strips).
            if sum(class_rays[f"fixed {n}"][k] for k, n in enumerate(combo)) <= rays[label]:
                e = float(np.sqrt(sum(share[k] * mse[n][k] for k, n in enumerate(combo))))
                if best is None or e < best[0]:
                    best = (e, combo)
        at = fixed_error_at(fixed_curve, rays[label])
        if best is None or at is None:
            continue
        got = float(np.sqrt(np.mean([np.mean((im - truth) ** 2) for im in images[label]])))
        rule = ", ".join(f"{r:g}: {n}" for r, n in zip(values, best[1]))
        print(f"  best roughness -> rays map for {label}'s {budget:.2f} rays per pixel (emulated): {{{rule}}} "
              f"RMSE {best[0]:.5f}; {label} {got:.5f}; fixed rays at the same rays {at:.5f}")


def adaptive_verdicts(summary, n):
    """Equal-time verdicts: each adaptive row's error against the fixed rows' error at the same
    time (log-log interpolation). Decided only where the ranges do not overlap: the adaptive
    frames' min-max error against the fixed curve taken at the adaptive row's min and max time,
    with the fixed rows' own min-max errors."""
    for key, name in ((0, "trace"), (1, "trace+resolve")):
        fixed = sorted((statistics.median(t[key]), statistics.mean(e), min(e), max(e))
                       for c, t, e in summary.values() if c is not None)
        lo_curve = [(t, lo) for t, _, lo, _ in fixed]
        hi_curve = [(t, hi) for t, _, _, hi in fixed]
        mean_curve = [(t, m) for t, m, _, _ in fixed]
        for label, (count, t, e) in summary.items():
            if count is not None:
                continue
            tm, tlo, thi = statistics.median(t[key]), min(t[key]), max(t[key])
            at = fixed_error_at(mean_curve, tm)
            if at is None:
                print(f"  equal {name} time, {label}: {tm:.1f} ms is outside the fixed rows' "
                      f"{fixed[0][0]:.1f}-{fixed[-1][0]:.1f} ms: no comparison")
                continue
            # The fixed curve's error range over the adaptive row's time range (clamped to the curve).
            ends = [fixed_error_at(c, min(max(x, fixed[0][0]), fixed[-1][0])) for c in (lo_curve, hi_curve)
                    for x in (tlo, thi)]
            f_lo, f_hi = min(ends), max(ends)
            if max(e) < f_lo:
                verdict = f"adaptive lower error, {100 * (1 - statistics.mean(e) / at):.0f} % below fixed"
            elif min(e) > f_hi:
                verdict = f"fixed lower error, adaptive {100 * (statistics.mean(e) / at - 1):.0f} % above"
            else:
                verdict = "undecided (the ranges overlap)"
            print(f"  equal {name} time, {label}: RMSE {statistics.mean(e):.5f} ({min(e):.5f}-{max(e):.5f}) at "
                  f"{tm:.1f} ms; fixed rays at that time {at:.5f} ({f_lo:.5f}-{f_hi:.5f}): {verdict}")


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=7)
    # Defaults per section (--width/--height set all): the shares and the peeling at 640x360, the
    # resolution of the roofline's targets (at 320x180 a fixed ~0.3 ms per frame, the clears and
    # the empty dispatches, is already 5 % of a whole Hi-Z mirror frame on llvmpipe); the
    # adaptive section, 8 seeds of many rows, at 320x180.
    ap.set_defaults(width=None, height=None)
    ap.add_argument("--shares", type=float, nargs="+", default=[0, 1, 10, 50, 100])
    ap.add_argument("--sections", nargs="+", default=["shares", "peel", "adaptive"],
                    choices=("shares", "peel", "adaptive"))
    ap.add_argument("--reference-rays", type=int, default=1024)
    ap.add_argument("--error-seeds", type=int, default=8, help="adaptive: frames per row (at least --repeats)")
    ap.add_argument("--adaptive-walls", nargs="+", default=["checker"], choices=("checker", "smooth"))
    ap.add_argument("--adaptive-mixes", nargs="+", default=list(ADAPTIVE_MIXES), choices=tuple(ADAPTIVE_MIXES))
    ap.add_argument("--adaptive-reuse", type=int, nargs="+", default=[1, 0], choices=(0, 1, 2))
    ap.add_argument("--adaptive-methods", nargs="+", default=["bvh", "hiz"], choices=("bvh", "hiz", "linear"))
    args = ap.parse_args()
    r = open_renderer(args)
    global BENCH
    BENCH = Bench("skip", args, r)

    def sized(width, height):
        return argparse.Namespace(**{**vars(args), "width": args.width or width, "height": args.height or height})

    for name, section, size in (("shares", shares_section, (640, 360)), ("peel", peel_section, (640, 360)),
                                ("adaptive", adaptive_section, (320, 180))):
        if name in args.sections:
            a = sized(*size)
            print(f"{name}: {a.width}x{a.height}, median (min-max) of {a.repeats} runs after 2 warm-up runs; GPU ms\n")
            section(r, a)


if __name__ == "__main__":
    main()
