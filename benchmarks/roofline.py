"""A roofline of the frame (Williams et al. 2009): every pass against what the device can do, in one run.

    python benchmarks/roofline.py [--width 640 --height 360] [--scenes hall spheres_and_boxes]
                                  [--repeats 5] [--baseline base.json] [--device auto|gpu|cpu] [--quick]

1. The device's peaks, through ssrlab's own EGL context and the frame's texture formats
   (Renderer.microbenchmark, shaders/tools/microbench.comp): coherent texelFetch rate,
   dependent (pointer-chasing) texelFetch rate, the same chain by imageLoad (the path the passes
   read float inputs by on the CPU device, Renderer.info["input_fetch"]: llvmpipe runs it about
   twice as fast), imageStore rate, streaming read bandwidth, and
   a trivial copy pass of one RGBA texture of the frame's size (the floor of a full-screen pass;
   also reading by imageLoad, as the passes do on the CPU device).
2. The frame at two configurations per scene: the thesis's (4 layers, 4 GGX rays, half
   resolution, stride 4, 250 steps, linear tracing) and one layer of Hi-Z mirror rays, one ray
   per pixel, reuse radius 1 (the issue's resolve-vs-trace pair).
   Per pass: median GPU time (min-max) of `repeats` renders after a warm-up (timings never
   include compilation or first use), its counted work (fetches, bytes read and written: the
   tracers' depth fetches are counted by the shaders, the rest derived from the dispatch sizes,
   the formats and the ray-list counters; the model is `work_of` below), the achieved rate and
   its share of the matching peak (coherent fetches; dependent fetches for the tracers, with their
   share of the imageLoad chain's rate beside it).
3. The issue's ratios: composite / copy pass, resolve / Hi-Z trace (hall, 1 ray, radius 1),
   the Hi-Z trace's share of the dependent-fetch rate (the issue's peak, the texelFetch chain; its
   share of the imageLoad chain's rate is printed too, without a target; copy and dependent
   kernels at the frame's size, run between the frames so that both sides of a ratio see the same
   load), and the thesis-configuration frame
   against a recorded baseline (--baseline: a JSON {"<scene>": total_ms} or the output of an
   earlier run's --json), or, better, measured in the same run against another shader tree
   (--baseline-shaders DIR, e.g. `git archive main shaders | tar -x -C /tmp/main`: the frames of
   both renderers interleaved, at both configurations, with every pass's time before and now and
   the thesis error between their images).
   Each ratio is taken once per repeat, from the pair of timings measured at the same moments,
   and printed as the median with the middle half of the repeats (25th-75th percentile); the
   verdict against the issue's target is "met" or "not met" only when that middle half lies on
   one side of it, else "too small to judge" (ssrlab.lab.timing.target_verdict).
4. A render call's CPU overhead: wall time of render() plus reading frame.color against the GPU
   total, and the readback alone.

Timings on llvmpipe are CPU time on shared cores: compare ratios from one run, never absolute
figures across runs. The same command runs on a GPU (--device gpu).
"""

from __future__ import annotations

import json
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import benchmark_arguments, open_renderer  # noqa: E402

from ssrlab.lab.timing import median_range as spread, paired  # noqa: E402

THESIS = dict(layers=4, rays_per_pixel=4, stride=4.0, downscale=2, max_steps=250)
# The resolve-vs-trace pair: one layer, Hi-Z mirror rays, 1 ray, reuse radius 1.
HIZ_MIRROR = dict(layers=1, method="hiz", sampling="mirror", rays_per_pixel=1, reuse_radius=1)

# name: (kernel, operations per texel, bytes read per operation, bytes written per operation)
PEAKS = {
    "coherent": ("coherent", 64, 8, 0),     # RG32F texelFetch, addresses known up front
    "dependent": ("dependent", 64, 8, 0),   # RG32F texelFetch, address from the previous one
    "dependent_image": ("dependent_image", 64, 8, 0),  # the same chain by imageLoad
    "store": ("store", 8, 0, 8),            # RGBA16F imageStore
    "bandwidth": ("bandwidth", 8, 16, 0),   # RGBA32F texelFetch, each texel once
}


def measure_peaks(renderer, width, height, frame_width, frame_height, repeats):
    """Operations (and bytes) per second of each micro-kernel; the copy pass at the frame's size."""
    out = {}
    for name, (kernel, its, rd, wr) in PEAKS.items():
        ms = renderer.microbenchmark(kernel, width, height, its, repeats)
        med, lo, hi = spread(ms)
        ops = width * height * its
        out[name] = dict(ms=med, lo=lo, hi=hi, ops=ops, rate=ops / (med * 1e-3), bytes_rate=ops * (rd + wr) / (med * 1e-3))
    px = frame_width * frame_height
    for name in ("copy", "copy_image"):
        ms = renderer.microbenchmark(name, frame_width, frame_height, 1, repeats)
        med, lo, hi = spread(ms)
        out[name] = dict(ms=med, lo=lo, hi=hi, ops=px, rate=px / (med * 1e-3), bytes_rate=px * 24 / (med * 1e-3))
    return out


def work_of(pass_name, s, stats, passes=()):
    """Counted work of one pass: (fetches, bytes read, bytes written, peak it is bound by), or None
    for the rasterising passes (shadow_map, depth_peel), which the compute roofline does not model.
    Derived from the dispatch sizes, the formats (RGBA16F 8 B, RGBA32F 16 B, R32F 4 B, RG32F 8 B,
    RGBA8/SRGB8_A8 4 B) and the shaders' own counters in frame.stats; `passes`: the frame's chain
    (with resolve_fetch the resolve reads its neighbours' rays from its textures)."""
    px = s.width * s.height
    layers_lit = stats.get("layers_lit", s.layers)
    tw, th = (s.width + s.downscale - 1) // s.downscale, (s.height + s.downscale - 1) // s.downscale
    trace_px = tw * th
    rays = stats.get("rays_traced", trace_px * s.rays_per_pixel)
    if pass_name == "lighting":
        # (r+1)^2 hardware-compare taps of 4 texels each; only the covered 8x8 tiles
        # (stats["tiles_lit"]) are shaded, the rest of each layer is cleared (not counted).
        taps = (s.shadow_pcf_radius + 1) ** 2
        texels = stats["tiles_lit"] * 64 if stats.get("tiles_lit", -1) >= 0 else px * layers_lit
        f = texels * (4 + 4 * taps)
        return f, texels * (4 + 4 + 8 + 4 + taps * 16), texels * (8 + 4), "coherent"
    if pass_name == "classify":
        # The reflectivity of every pixel of the 32x32 regions the peeling flagged
        # (gathered 2x2; the examined trace pixels scaled to full resolution), the G-buffer of the
        # reflective ones (3 more fetches; counted as the resolve list's receivers and rough
        # pixels); writes: the clears of rays.sample (RGBA32F per trace pixel and ray) and of the
        # reflection, and the list entries.
        reflective = stats.get("resolve_pixels", stats.get("pixels_traced", 0)) + stats.get("environment_pixels", 0)
        examined = int(stats.get("pixels_classified", trace_px) * px / max(trace_px, 1))
        f = examined + 3 * reflective
        written = trace_px * s.rays_per_pixel * 16 + (px * 8 if "resolve_groups" in stats else 0) + rays * 4
        return f, examined * 4 + reflective * 16, written, "coherent"
    if pass_name == "hiz_build":
        f = int(px * s.layers * 4 / 3)
        # The coarser levels, and with method="hiz" every level again into the tracer's atlas.
        written = int(px * s.layers / 3) * 8 + (f * 8 if s.method == "hiz" else 0)
        return f, f * 8, written, "coherent"
    if pass_name in ("trace_hiz", "trace_linear"):
        f = stats.get("depth_fetches", 0)
        texel = 8 if pass_name == "trace_hiz" else 4
        return f, f * texel + rays * 16, rays * 24, "dependent"
    if pass_name == "resolve_fetch":
        # Every (trace pixel, ray) slot: the pixel's sample flag and depth, the ray's hit, sample
        # and direction, and for a hit its lit colour and depth (an upper bound: as if every ray
        # hit); two RGBA32F stores.
        slots = trace_px * s.rays_per_pixel
        return slots * 7, slots * (16 + 4 + 3 * 16 + 8 + 4), slots * 32, "coherent"
    if pass_name == "resolve" and "resolve_fetch" in passes:
        # Every pixel its G-buffer (3); a receiving pixel (about the traced pixels' footprint at
        # full resolution), per neighbour within reuse_radius, that neighbour's sample flag, normal
        # and depth and two RGBA32F texels per ray (resolve_fetch's). With skip only the listed
        # 16x16 tiles run.
        group, n = 16, (2 * s.reuse_radius + 1) ** 2
        run = stats.get("resolve_tiles", px / group ** 2) * group ** 2
        receivers = min(run, stats.get("pixels_traced", trace_px) * s.downscale ** 2)
        f = int(run * 3 + receivers * n * (3 + 2 * s.rays_per_pixel))
        read = int(run * 16 + receivers * n * (16 + 8 + 4 + 32 * s.rays_per_pixel))
        return f, read, int(run * 8), "coherent"
    if pass_name == "resolve":
        # Every pixel: its normal, material and depth (3). Own-rays-only path (full resolution,
        # radius 0 or mirror rays with BRDF weights): each traced pixel's sample flag and its rays'
        # hit, sample, direction, lit colour and hit depth (1 + 5 per ray). Tiled path: an upper
        # bound, as if every group held a receiver: per tile entry its origin (3) and 5 per ray.
        # With skip only the listed receiving pixels (own rays) or 16x16 tiles run.
        own = s.downscale == 1 and (s.reuse_radius == 0 or (s.sampling == "mirror" and s.reuse_weighting == "brdf"))
        if own:
            run = stats.get("resolve_pixels", px)
            f = run * 3 + stats.get("pixels_traced", px) * (1 + 5 * s.rays_per_pixel)
        else:
            group, radius = 16, s.reuse_radius
            run = stats.get("resolve_tiles", px / group ** 2) * group ** 2
            tile = ((group // s.downscale) + 2 * radius + 1) ** 2
            f = int(run * (3 + tile / group ** 2 * (3 + 5 * s.rays_per_pixel)))
        return f, f * 8, int(run * 8), "coherent"
    if pass_name == "composite":
        # lit (its alpha carries coverage and r) and the reflection; RGBA32F out.
        return px * 2, px * (8 + 8), px * 16, "coherent"
    return None


def run_config(renderer, scene, settings, repeats):
    """Median, min, max GPU ms per pass (top-level keys) of `repeats` renders after warm-ups, the
    last frame's stats, and the CPU side of a render call."""
    for _ in range(2):
        renderer.render(scene, settings=settings).color
    runs, walls, reads, peaks = [], [], [], {"copy": [], "copy_image": [], "dependent": [], "dependent_image": []}
    frame = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        frame = renderer.render(scene, settings=settings)
        t1 = time.perf_counter()
        frame.color
        t2 = time.perf_counter()
        runs.append(frame.timings)
        walls.append((t2 - t0) * 1e3)
        reads.append((t2 - t1) * 1e3)
        # The peaks the ratios use, between the frames: on a shared machine (llvmpipe on busy
        # cores) the load changes within seconds, so a ratio takes both sides at the same moments.
        peaks["copy"] += renderer.microbenchmark("copy", settings.width, settings.height, 1, 1)
        peaks["copy_image"] += renderer.microbenchmark("copy_image", settings.width, settings.height, 1, 1)
        peaks["dependent"] += renderer.microbenchmark("dependent", settings.width, settings.height, 64, 1)
        peaks["dependent_image"] += renderer.microbenchmark("dependent_image", settings.width, settings.height, 64, 1)
    keys = [k for k in runs[0] if "." not in k]
    stats = dict(frame.stats)  # rays_traced, depth_fetches: summed from rays.sample, skip on or off
    return ({k: spread([r[k] for r in runs]) for k in keys}, stats,
            dict(wall=spread(walls), readback=spread(reads), copy=spread(peaks["copy"]),
                 dependent=spread(peaks["dependent"]), dependent_image=spread(peaks["dependent_image"]),
                 # every repeat's timings, for ratios taken pair by pair
                 each=dict(runs=runs, copy=peaks["copy"], copy_image=peaks["copy_image"], dependent=peaks["dependent"],
                           dependent_image=peaks["dependent_image"])))


def ab_shaders(before, now, scene, settings, key, repeats, ratios):
    # ratios: key -> every repeat's value (the caller takes medians and verdicts)
    """Frames of two renderers (two shader trees) interleaved: every pass's median before and now
    and the error between their images; the frame and resolve ratios go into `ratios`."""
    from ssrlab import metrics

    for r in (before, now):
        for _ in range(2):
            r.render(scene, settings=settings)
    per_pass = {}  # pass: (before, now) timings of every pass both frames ran
    for _ in range(repeats):
        fb, fn = before.render(scene, settings=settings), now.render(scene, settings=settings)
        for k in fb.timings.keys() & fn.timings.keys():
            per_pass.setdefault(k, ([], []))
            per_pass[k][0].append(fb.timings[k])
            per_pass[k][1].append(fn.timings[k])
    err = metrics.thesis_error(fn.color, fb.color)
    diff = float(abs(fn.color - fb.color).sum(axis=-1).max())
    print(f"{key}: thesis error of the image {err:.2e}, largest per-pixel error {diff:.2e}")
    for k in sorted(per_pass):
        b, n = per_pass[k]
        print(f"  {k}: before {statistics.median(b):.2f} ms ({min(b):.2f}-{max(b):.2f}), now "
              f"{statistics.median(n):.2f} ms ({min(n):.2f}-{max(n):.2f}), now / before "
              f"{statistics.median(n) / statistics.median(b):.3f}")
    # Not the speed-up target, which is against 069e706 (benchmarks/ab_frame.py).
    ratios[f"{key}: frame before / now, same run"] = paired(*per_pass["total"])
    if "resolve" in per_pass:
        ratios[f"{key}: resolve before / now, same run"] = paired(*per_pass["resolve"])


def fmt_rate(x):
    for unit, div in (("G", 1e9), ("M", 1e6), ("k", 1e3)):
        if x >= div:
            return f"{x / div:.2f} {unit}"
    return f"{x:.0f} "


def main(argv=None) -> int:
    ap = benchmark_arguments(__doc__, repeats=5)
    ap.set_defaults(scenes=["hall", "spheres_and_boxes"])
    ap.add_argument("--micro-width", type=int, default=1280, help="grid of the peak kernels")
    ap.add_argument("--micro-height", type=int, default=720)
    ap.add_argument("--baseline", help="JSON {scene: thesis-config frame total ms} recorded before a change")
    ap.add_argument("--baseline-shaders", help="shader folder of the code before a change: frames of both at both "
                    "configurations, interleaved in this run, and the thesis error between their images")
    ap.add_argument("--json", help="write every figure to this JSON file")
    ap.add_argument("--quick", action="store_true", help="tiny sizes, 2 repeats: a smoke run, not figures")
    args = ap.parse_args(argv)
    if args.quick:
        args.width, args.height, args.micro_width, args.micro_height, args.repeats = 96, 64, 64, 64, 2
        args.scenes = args.scenes[:1]

    import ssrlab
    from ssrlab.lab.timing import target_verdict

    renderer = open_renderer(args)
    print(f"frame {args.width}x{args.height}, peaks at {args.micro_width}x{args.micro_height}, "
          f"medians (min-max) of {args.repeats} after warm-up")
    peaks = measure_peaks(renderer, args.micro_width, args.micro_height,
                          args.width, args.height, args.repeats)
    print("\n| peak | ms (min-max) | rate /s | bytes /s |\n|---|---|---|---|")
    for name, p in peaks.items():
        print(f"| {name} | {p['ms']:.2f} ({p['lo']:.2f}-{p['hi']:.2f}) | {fmt_rate(p['rate'])} | "
              f"{fmt_rate(p['bytes_rate'])}B |")

    result = {"device": renderer.info["renderer"], "peaks": peaks, "configs": {}, "ratios": {}, "ratio_repeats": {}}
    each = {}  # config -> every repeat's timings
    configs = {"thesis": THESIS, "hiz_mirror": HIZ_MIRROR}
    for scene_name in args.scenes:
        scene = getattr(ssrlab.scenes, scene_name)()
        for cname, kw in configs.items():
            s = ssrlab.Settings(width=args.width, height=args.height, **kw)
            times, stats, cpu = run_config(renderer, scene, s, args.repeats)
            rows = {}
            print(f"\n{scene_name} {cname} ({', '.join(f'{k}={v}' for k, v in kw.items())})")
            print("| pass | ms (min-max) | fetches | read B | written B | rate /s | share of peak |")
            print("|---|---|---|---|---|---|---|")
            for name, (med, lo, hi) in times.items():
                w = work_of(name, s, stats, tuple(times))
                row = dict(ms=med, lo=lo, hi=hi)
                if w is None or name == "total" or med <= 0:
                    print(f"| {name} | {med:.2f} ({lo:.2f}-{hi:.2f}) | | | | | |")
                else:
                    f, rd, wr, bound = w
                    rate = f / (med * 1e-3)
                    share = rate / peaks[bound]["rate"]
                    row.update(fetches=f, bytes_read=rd, bytes_written=wr, rate=rate, share=share, bound=bound)
                    also = ""
                    if bound == "dependent":
                        row["share_image"] = rate / peaks["dependent_image"]["rate"]
                        also = f" ({100 * row['share_image']:.1f} % of dependent_image)"
                    print(f"| {name} | {med:.2f} ({lo:.2f}-{hi:.2f}) | {f:,} | {rd:,} | {wr:,} | "
                          f"{fmt_rate(rate)} | {100 * share:.1f} % of {bound}{also} |")
                rows[name] = row
            print(f"render() + frame.color wall {cpu['wall'][0]:.1f} ms against GPU total "
                  f"{times['total'][0]:.1f} ms (CPU-side overhead {cpu['wall'][0] - times['total'][0]:.1f} ms), "
                  f"color readback {cpu['readback'][0]:.1f} ms")
            px = s.width * s.height
            dep_rate = px * 64 / (cpu["dependent"][0] * 1e-3)
            dep_image_rate = px * 64 / (cpu["dependent_image"][0] * 1e-3)
            print(f"interleaved peaks: copy pass {cpu['copy'][0]:.2f} ms ({cpu['copy'][1]:.2f}-{cpu['copy'][2]:.2f}), "
                  f"dependent fetches {fmt_rate(dep_rate)}/s, by imageLoad {fmt_rate(dep_image_rate)}/s")
            result["configs"][f"{scene_name}/{cname}"] = dict(
                passes=rows, stats=stats, wall_ms=cpu["wall"][0], readback_ms=cpu["readback"][0],
                copy_ms=cpu["copy"][0], dependent_rate=dep_rate, dependent_image_rate=dep_image_rate)
            each[f"{scene_name}/{cname}"] = dict(cpu["each"], px=px)

    ratios = {}  # key -> every repeat's value
    for key, cfg in result["configs"].items():
        p, e = cfg["passes"], each[key]
        ms = {name: [r[name] for r in e["runs"]] for name in ("composite", "trace_hiz", "resolve", "total")
              if name in p}
        if "composite" in p:
            ratios[f"{key}: composite / copy"] = paired(ms["composite"], e["copy"])
            # The same against a copy that reads by imageLoad, as the composite does on the CPU
            # device (input_fetch): no target (the copy pass reads by texelFetch).
            ratios[f"{key}: composite / copy by imageLoad"] = paired(ms["composite"], e["copy_image"])
        if "trace_hiz" in p and "rate" in p["trace_hiz"]:
            # (fetches / trace time) / (the dependent kernel's fetches / its time), repeat by repeat
            ratios[f"{key}: trace_hiz share of dependent-fetch rate"] = [
                p["trace_hiz"]["fetches"] / (e["px"] * 64) * dep / t for t, dep in zip(ms["trace_hiz"], e["dependent"])]
            # The same against the imageLoad chain, the faster of the two on llvmpipe and the path
            # the trace reads its pyramid by there: no target (the peak is texelFetch's).
            ratios[f"{key}: trace_hiz share of the dependent imageLoad rate"] = [
                p["trace_hiz"]["fetches"] / (e["px"] * 64) * dep / t
                for t, dep in zip(ms["trace_hiz"], e["dependent_image"])]
    for key, cfg in result["configs"].items():
        p = cfg["passes"]
        if "trace_hiz" in p and "resolve" in p:
            runs = each[key]["runs"]
            ratios[f"{key}: resolve / trace_hiz"] = paired([r["resolve"] for r in runs], [r["trace_hiz"] for r in runs])
    if args.baseline:
        base = json.loads(Path(args.baseline).read_text())
        for scene_name in args.scenes:
            b = base.get(scene_name)
            cur = each.get(f"{scene_name}/thesis")
            if b and cur:
                ratios[f"{scene_name}/thesis: baseline / now (frame speed-up)"] = [b / r["total"] for r in cur["runs"]]
    if args.baseline_shaders:
        print(f"\nagainst the shaders in {args.baseline_shaders} (frames interleaved, this run)")
        before = ssrlab.Renderer(args.device, shader_dir=args.baseline_shaders)
        for scene_name in args.scenes:
            scene = getattr(ssrlab.scenes, scene_name)()
            for cname, kw in configs.items():
                s = ssrlab.Settings(width=args.width, height=args.height, **kw)
                ab_shaders(before, renderer, scene, s, f"{scene_name}/{cname}", args.repeats, ratios)
    targets = {"composite / copy": ("<=", 2.0), "resolve / trace_hiz": ("<=", 0.6),
               "share of dependent-fetch rate": (">=", 0.25), "speed-up": (">=", 2.0)}
    print("\nratios (the targets; median of the repeats' paired ratios [middle half])")
    for k, values in ratios.items():
        v = float(np.median(values))
        q1, q3 = np.percentile(values, [25, 75])
        result["ratios"][k] = v
        result["ratio_repeats"][k] = [float(x) for x in values]
        # The targets are set against its texelFetch kernels; the imageLoad ratios have none.
        op, goal = next((t for name, t in targets.items() if name in k and "imageLoad" not in k), ("", None))
        verdict = "" if goal is None else f"  (target {op} {goal}: {target_verdict(values, op, goal)})"
        print(f"  {k}: {v:.3g} [{q1:.3g}-{q3:.3g}]{verdict}")
    bad = [k for k, v in result["ratios"].items() if not math.isfinite(v)]
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1, default=float))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
