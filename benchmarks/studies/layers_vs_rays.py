"""Seed 000, 4.2 re-judged: is frame time better spent on deep G-buffer layers or on rays?

    python benchmarks/studies/layers_vs_rays.py [--width 320 --height 180 --repeats 5 --reference-rays 64
                                         --scenes occluder box_stack hall
                                         --deep-gbuffer peel lists visibility visibility_lists]

The thesis found that extra layers improve the reflections but that "the time spent
constructing the deep G-buffers is better spent on other parts of rendering" (seed 000, 4.2),
with layers built by depth peeling (one geometry pass each). Here the layers can be built by any
exact construction of Settings.deep_gbuffer (docs/deep_gbuffer.md: 'peel', 'lists' in one
geometry pass, 'visibility' and 'visibility_lists' rasterising depth and a triangle id only, or
'auto', which the Renderer decides by measuring), and the same frame time can go to the rays
instead. From the thesis's configuration with one layer (seed 000, 3.2: 4 rays a pixel, stride 4,
half resolution, 250 steps; the plain G-buffer, peeled) three ways to spend more time:

  layers (X)       2, 3, 4 layers built by construction X, for each X of --deep-gbuffer
                   (default the four exact constructions; peeling, the thesis's, always)
  layers (fastest) at each layer count, the construction whose median time (on the clock being
                   judged) was the lowest in this run: the layers as fast as this device builds them
  rays             8, 16 rays a pixel, or rays traced at full resolution (1 layer)
  steps            stride 2, 1: more, shorter steps per ray (1 layer)

Every configuration renders `repeats` single frames, with seeds 0..repeats-1, after the
protocol's 2 warm-up rounds, configurations interleaved round by round (ssrlab.lab.protocol);
every time and error is a record with one sample per seed, and the tables are rendered from them. Time: the median GPU time of the whole
frame (timings['total']) and its interquartile range; on llvmpipe also the CPU time the process
spent in the render call (its rasteriser threads included): llvmpipe's GPU timer measures wall
time, which a machine shared with other jobs inflates (most at each CPU-GPU synchronisation, and
the lists synchronise more often than peeling), while the CPU time counts the work done. Each
clock gets its own verdict. Error: thesis_error_reflective against the
converged reference (ssrlab.reference, `reference-rays` rays a pixel), mean over the seeds.
For each configuration: the error removed against the 1-layer start (paired by seed, with its
standard error), the time added, and their ratio, the error removed per millisecond. A gain is
"measured" where it exceeds twice its standard error and the time added exceeds the two
configurations' IQRs summed (and 1 ms); otherwise it is noise. Per scene the verdict compares the
best measured ratio of layers (fastest) with the best measured ratio of rays or steps: the one
whose ratio is higher by more than twice the combined standard error of the two ratios wins
(the ratio's error counts the error's noise; the time counts only once beyond its noise). A side
none of whose configurations removed error beyond noise loses to a side with a measured ratio;
where a side removed error but its time could not be told from noise, or the ratios are within
their errors, the verdict says the data is too noisy to tell. The same for each construction's
series, the thesis's (peel) among them, for the comparison with the thesis's verdict. (Taking the
fastest of several constructions measured in the same repeats favours the layers a little: the
least of noisy medians is biased low. The per-construction verdicts have no such bias.)
"""

from __future__ import annotations

import sys
from pathlib import Path
import math
import statistics
import time

import numpy as np

import ssrlab

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab import records  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402
from ssrlab.experiments import MIN_JUDGED_MS, THESIS_SETTINGS  # noqa: E402
from ssrlab.metrics import image_metrics  # noqa: E402
from ssrlab.reference import reference_image  # noqa: E402

SCENES = {
    "occluder": ("spheres_and_boxes(with_suzanne=True)",
                 lambda: ssrlab.scenes.load("spheres_and_boxes", with_suzanne=True)),
    "spheres_and_boxes": ("spheres_and_boxes", lambda: ssrlab.scenes.load("spheres_and_boxes")),
    "box_stack": ("box_stack", lambda: ssrlab.scenes.load("box_stack")),
    "hall": ("hall", lambda: ssrlab.scenes.load("hall")),
}
ERROR = "thesis_error_reflective"
CLOCKS = {
    "gpu": "gpu = the GPU timer of the whole frame (timings['total'])",
    # llvmpipe's timer measures wall time, which on a shared machine includes the waits for a
    # core (longest at every CPU-GPU synchronisation); the process's CPU time counts the work its
    # rasteriser threads did, whatever else runs.
    "cpu": "cpu = the CPU time this process (llvmpipe's threads included) spent in the render call",
}
TOO_NOISY = "too noisy to tell"


CONSTRUCTIONS = ("peel", "lists", "visibility", "visibility_lists")  # the exact ones (docs/deep_gbuffer.md)
LAYERS = (2, 3, 4)
FASTEST = "layers (fastest)"


def layer_series(construction: str) -> str:
    return f"layers ({construction})"


def configurations(base: ssrlab.Settings, constructions=CONSTRUCTIONS) -> dict[tuple[str, str], ssrlab.Settings]:
    """(series, label) -> settings; the start is ("start", "1 layer"); a series of layers per
    construction (peeling, the thesis's, always among them)."""
    start = base.replace(layers=1, deep_gbuffer="peel")
    out = {("start", "1 layer"): start}
    for construction in dict.fromkeys(["peel", *constructions]):
        for layers in LAYERS:
            out[(layer_series(construction), f"{layers} layers")] = base.replace(layers=layers,
                                                                                  deep_gbuffer=construction)
    for rays in (8, 16):
        out[("rays", f"{rays} rays")] = start.replace(rays_per_pixel=rays)
    out[("rays", "full res")] = start.replace(downscale=1)  # rays traced for every pixel: 4x the rays
    for stride in (2.0, 1.0):
        out[("steps", f"stride {stride:g}")] = start.replace(stride=stride)
    return out


def iqr(values) -> float:
    q1, q3 = np.percentile(np.asarray(values, float), [25, 75])
    return float(q3 - q1)


def judge(a, b, name_a: str, name_b: str) -> str:
    """Which series removes more error per millisecond (see the module notes). a and b are a
    series' best measured configuration as (ratio, standard error of the ratio, label), or
    "no gain" (no configuration of it removed error beyond noise), or "noisy" (one removed
    error, but its added time was within the times' noise)."""
    if isinstance(a, tuple) and isinstance(b, tuple):
        (ra, sa, la), (rb, sb, lb) = a, b
        margin = 2 * math.hypot(sa, sb)
        if abs(ra - rb) <= margin:
            return (f"{TOO_NOISY}: {name_a} ({la}) {ra:.2e} vs {name_b} ({lb}) {rb:.2e} error/ms differ by no "
                    f"more than twice their standard error ({margin:.1e})")
        (wn, wl, wr), (ln, ll, lr) = ((name_a, la, ra), (name_b, lb, rb)) if ra > rb else ((name_b, lb, rb),
                                                                                       (name_a, la, ra))
        return f"{wn} ({wl}: {wr:.2e} error/ms, {wr / lr:.1f}x {ln}'s best, {ll}: {lr:.2e})"
    if isinstance(a, tuple) and b == "no gain":
        return f"{name_a} ({a[2]}: {a[0]:.2e} error/ms; {name_b} removed no error beyond noise)"
    if isinstance(b, tuple) and a == "no gain":
        return f"{name_b} ({b[2]}: {b[0]:.2e} error/ms; {name_a} removed no error beyond noise)"
    if a == "no gain" and b == "no gain":
        return f"neither: no configuration of {name_a} or {name_b} removed error beyond noise"
    noisy = [n for n, v in ((name_a, a), (name_b, b)) if v == "noisy"]
    return f"{TOO_NOISY}: the time {' and '.join(noisy)} added is within the times' noise"


def series_result(results: list) -> tuple | str:
    """A series' configurations, (ratio, ratio s.e., label, gain measured, time measured) each,
    summed up for judge()."""
    measured = [r[:3] for r in results if r[3] and r[4]]
    if measured:
        return max(measured, key=lambda r: r[0])
    return "noisy" if any(r[3] for r in results) else "no gain"


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=5)
    ap.set_defaults(width=320, height=180, scenes=["occluder", "box_stack", "hall"])
    ap.add_argument("--reference-rays", type=int, default=64)
    ap.add_argument("--deep-gbuffer", nargs="+", default=list(CONSTRUCTIONS), choices=(*CONSTRUCTIONS, "auto"),
                    help="the constructions whose layers are measured (peeling always is); 'auto': the one the "
                         "Renderer measures fastest for each layer count (Settings.deep_gbuffer='auto')")
    args = ap.parse_args()
    if args.repeats < 3:
        ap.error("--repeats must be at least 3 (the spread of times and errors is measured over them)")
    unknown = [s for s in args.scenes if s not in SCENES]
    if unknown:
        ap.error(f"--scenes: unknown {unknown}; choose from {list(SCENES)}")
    renderer = open_renderer(args)
    bench = Bench("layers_vs_rays", args, renderer)
    base = ssrlab.Settings(width=args.width, height=args.height, **THESIS_SETTINGS)
    configs = configurations(base, args.deep_gbuffer)
    constructions = list(dict.fromkeys(["peel", *args.deep_gbuffer]))
    clocks = ["gpu"] + (["cpu"] if renderer.info["device"] == "cpu" else [])
    print(f"{args.width}x{args.height}, from the thesis settings {THESIS_SETTINGS} with 1 layer; {args.repeats} "
          f"frames per configuration (seeds 0-{args.repeats - 1}) after {bench.warmup} warm-up rounds, interleaved; error: {ERROR} "
          f"against {args.reference_rays}-ray converged references, mean over the seeds; time, median [IQR]: "
          + "; ".join(CLOCKS[c] for c in clocks) + "\n")
    summary = []
    for key in args.scenes:
        label, make = SCENES[key]
        scene = make()
        ref = reference_image(renderer, scene, scene.camera, base, kind="converged", rays=args.reference_rays)
        used = {c: None for c in configs}
        state = {"round": -1}

        def measure(c, s):
            def run():
                if c == first:
                    state["round"] += 1
                seed = max(state["round"] - bench.warmup, 0)  # the warm-up rounds render seed 0
                cpu0 = time.process_time()
                f = renderer.render(scene, settings=s.replace(seed=seed))
                cpu = 1000.0 * (time.process_time() - cpu0)
                out = {"gpu": f.timings["total"], "error": image_metrics(f.color, ref.color, ref.reflective,
                                                                         perceptual=False)[ERROR]}
                if "cpu" in clocks:
                    out["cpu"] = cpu
                used[c] = (f.stats["layers_used"], f.stats.get("deep_gbuffer_method", f.settings.deep_gbuffer))
                f.release()
                return out
            return run

        first = next(iter(configs))
        measured = bench.rounds({c: measure(c, s) for c, s in configs.items()})
        times, errors = {}, {}
        for c in configs:
            params = dict(scene=key, series=c[0], configuration=c[1], built_by=used[c][1], layers_used=used[c][0],
                          width=args.width, height=args.height, reference_rays=args.reference_rays)
            errors[c] = bench.record(params, ERROR, "", measured[c]["error"])["samples"]
            for clock in clocks:
                times[(clock, c)] = bench.record({**params, "clock": clock}, "frame", "ms",
                                                 measured[c][clock])["samples"]
        start = ("start", "1 layer")
        e0 = statistics.fmean(errors[start])
        print(f"{label} ({int(ref.reflective.sum())} reflective pixels): 1 layer, thesis settings: error {e0:.5f}, "
              + ", ".join(f"{clock} {statistics.median(times[(clock, start)]):.1f} ms" for clock in clocks))
        verdicts = {}
        for clock in clocks:
            t0 = statistics.median(times[(clock, start)])
            # At each layer count, the construction this clock found fastest (lowest median).
            fastest = {}
            for layers in LAYERS:
                label_l = f"{layers} layers"
                best = min((c for c in configs if c[0].startswith("layers (") and c[1] == label_l),
                           key=lambda c: statistics.median(times[(clock, c)]))
                fastest[(FASTEST, label_l)] = best
            print(f"  by {clock} time")
            results: dict[str, list] = {}
            table = []
            for c in [*configs, *fastest]:
                series, name = c
                m = fastest.get(c, c)  # the measured configuration behind the row
                ts = times[(clock, m)]
                t, e = statistics.median(ts), statistics.fmean(errors[m])
                row = [series, name, used[m][1], used[m][0], records.cell(ts, 1), f"{e:.5f}"]
                if c == start:
                    table.append(row + ["", "", "", ""])
                    continue
                gains = [a - b for a, b in zip(errors[start], errors[m])]  # paired by seed
                gain = statistics.fmean(gains)
                se = statistics.stdev(gains) / math.sqrt(len(gains))
                added = t - t0
                gain_measured = gain > 2 * se
                time_measured = added > max(iqr(ts) + iqr(times[(clock, start)]), MIN_JUDGED_MS)
                ratio = gain / added if added > 0 else float("nan")
                why = [w for ok, w in ((gain_measured, "gain within noise"), (time_measured, "time within noise"))
                       if not ok]
                table.append(row + [f"{gain:+.5f} ± {se:.5f}", f"{added:+.1f}", f"{ratio:.2e}",
                                    "yes" if not why else "no: " + ", ".join(why)])
                results.setdefault(series, []).append((ratio, se / added if added > 0 else float("nan"), name,
                                                       gain_measured, time_measured))
            print(records.markdown(["series", "configuration", "built by", "used", "ms [IQR]", "error",
                                    "removed (± s.e.)", "+ms", "error/ms", "measured?"], table))
            # Rays and steps together: the time spent on the rays.
            rays = series_result(results["rays"] + results["steps"])
            verdicts[clock] = {series: judge(series_result(results[series]), rays, series, "rays/steps")
                               for series in [FASTEST, *(layer_series(x) for x in constructions)]}
            print(f"  more error removed per {clock} ms, layers vs rays:")
            for series, v in verdicts[clock].items():
                print(f"    {series} -> {v}")
            print()
        summary.append((label, verdicts))
    print("seed 000, 4.2 (\"the time spent constructing the deep G-buffers is better spent on other parts of "
          "rendering\"), re-judged per scene with the layers built by the fastest exact construction (and by "
          "peeling, the thesis's):")
    for label, verdicts in summary:
        print(f"  {label}")
        for clock, v in verdicts.items():
            print(f"    by {clock} time, layers by the fastest construction: {v[FASTEST]}")
            print(f"    by {clock} time, layers by peeling:                  {v[layer_series('peel')]}")


if __name__ == "__main__":
    main()
