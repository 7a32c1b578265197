"""A roofline of the frame (Williams et al. 2009): every pass against what the device can do, in one run.

    python benchmarks/timing/roofline.py [--width 640 --height 360] [--scenes hall spheres_and_boxes]
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
   Per pass: GPU time over `repeats` rounds of the protocol after its warm-up rounds (timings
   never include compilation or first use; ssrlab.lab.protocol), its counted work (fetches, bytes read and written: the
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
   Each ratio is taken once per round, from the pair of timings measured at the same moments,
   and printed as the median with the middle half of the rounds (25th-75th percentile); the
   verdict against the issue's target is "met" or "not met" only when that middle half lies on
   one side of it, else undecided at this noise (ssrlab.lab.protocol.goal_verdict).
Every figure is a record (ssrlab.lab.records) with its samples; the tables are rendered from them.
4. A render call's CPU overhead: wall time of render() plus reading frame.color against the GPU
   total, and the readback alone.

Timings on llvmpipe are CPU time on shared cores: compare ratios from one run, never absolute
figures across runs. The same command runs on a GPU (--device gpu).
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402

from ssrlab.lab import records  # noqa: E402
from ssrlab.lab.protocol import Bench, goal_verdict  # noqa: E402
from ssrlab.lab.timing import paired  # noqa: E402

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


def measure_peaks(bench, renderer, width, height, frame_width, frame_height, repeats):
    """Records the ms (the kernel's own `repeats` timed dispatches) and the operations and bytes per
    second of each micro-kernel, the copy passes at the frame's size; returns {name: {ms, rate}},
    the medians (rate in operations a second)."""
    out = {}
    px = frame_width * frame_height
    kernels = {name: (kernel, its, rd + wr, width, height) for name, (kernel, its, rd, wr) in PEAKS.items()}
    kernels.update({name: (name, 1, 24, frame_width, frame_height) for name in ("copy", "copy_image")})
    for name, (kernel, its, nbytes, w, h) in kernels.items():
        ms = renderer.microbenchmark(kernel, w, h, its, repeats)
        ops = w * h * its if name not in ("copy", "copy_image") else px
        params = dict(peak=name, grid=f"{w}x{h}")
        bench.record(params, "ms", "ms", ms)
        rate = bench.record(params, "rate", "Gop/s", [ops / (m * 1e-3) / 1e9 for m in ms], better="higher")
        bench.record(params, "bytes_rate", "GB/s", [ops * nbytes / (m * 1e-3) / 1e9 for m in ms], better="higher")
        out[name] = dict(ms=float(np.median(ms)), rate=float(np.median(rate["samples"])) * 1e9)
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


def run_config(bench, renderer, scene, settings):
    """Every round's GPU ms per pass (top-level keys), the CPU side of a render call and the peak
    kernels at the frame's size run between the frames (bench.rounds after its warm-up rounds);
    and the last frame's stats."""
    last = {}

    def measure():
        t0 = time.perf_counter()
        frame = renderer.render(scene, settings=settings)
        t1 = time.perf_counter()
        frame.color
        t2 = time.perf_counter()
        last["stats"] = dict(frame.stats)  # rays_traced, depth_fetches: summed from rays.sample, skip on or off
        out = {k: v for k, v in frame.timings.items() if "." not in k}
        out.update({"cpu:wall": (t2 - t0) * 1e3, "cpu:readback": (t2 - t1) * 1e3})
        # The peaks the ratios use, between the frames: on a shared machine (llvmpipe on busy
        # cores) the load changes within seconds, so a ratio takes both sides at the same moments.
        w, h = settings.width, settings.height
        out["peak:copy"] = renderer.microbenchmark("copy", w, h, 1, 1)[0]
        out["peak:copy_image"] = renderer.microbenchmark("copy_image", w, h, 1, 1)[0]
        out["peak:dependent"] = renderer.microbenchmark("dependent", w, h, 64, 1)[0]
        out["peak:dependent_image"] = renderer.microbenchmark("dependent_image", w, h, 64, 1)[0]
        return out

    return bench.rounds({"frame": measure})["frame"], last["stats"]


def ab_shaders(bench, before, now, scene, settings, key, ratios):
    """Frames of two renderers (two shader trees) interleaved round by round: every pass's
    records on both sides (side "before" / "now") and the error between their images; the frame
    and resolve ratios before / now go into `ratios` (key -> every round's value)."""
    from ssrlab import metrics

    last = {}

    def render(name, r):
        def run():
            f = r.render(scene, settings=settings)
            last[name] = f
            return dict(f.timings)
        return run

    t = bench.rounds({"before": render("before", before), "now": render("now", now)})
    fb, fn = last["before"], last["now"]
    params = dict(config=key, width=settings.width, height=settings.height)
    bench.record({**params, "side": "now"}, "thesis_error_vs_before", "", [metrics.thesis_error(fn.color, fb.color)])
    bench.record({**params, "side": "now"}, "largest_pixel_error_vs_before", "",
                 [float(abs(fn.color - fb.color).sum(axis=-1).max())])
    common = [k for k in t["before"] if k in t["now"]]
    recs = []
    for side in ("before", "now"):
        for k in common:
            recs.append(bench.record({**params, "side": side, "pass": k}, "gpu", "ms", t[side][k]))
    print(f"\n{key}: before / now, this run")
    bench.print_ab("side", "before", "now", records=recs, rows=("config", "pass"))
    # The ratio within this run; the speed-up against commit 069e706 is measured by benchmarks/tools/ab_frame.py.
    ratios[f"{key}: frame before / now, same run"] = paired(t["before"]["total"], t["now"]["total"])
    if "resolve" in common:
        ratios[f"{key}: resolve before / now, same run"] = paired(t["before"]["resolve"], t["now"]["resolve"])


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

    renderer = open_renderer(args)
    bench = Bench("roofline", args, renderer)
    print(f"frame {args.width}x{args.height}, peaks at {args.micro_width}x{args.micro_height}, "
          f"{args.repeats} rounds after {bench.warmup} warm-up rounds")
    peaks = measure_peaks(bench, renderer, args.micro_width, args.micro_height, args.width, args.height, args.repeats)
    print()
    bench.print_table(rows=("peak", "grid"), order=["ms", "rate", "bytes_rate"], digits=3)

    result = {"device": renderer.info["renderer"], "peaks": peaks, "configs": {}, "ratios": {}, "ratio_repeats": {}}
    configs = {"thesis": THESIS, "hiz_mirror": HIZ_MIRROR}
    each = {}
    for scene_name in args.scenes:
        scene = getattr(ssrlab.scenes, scene_name)()
        for cname, kw in configs.items():
            s = ssrlab.Settings(width=args.width, height=args.height, **kw)
            runs, stats = run_config(bench, renderer, scene, s)
            key = f"{scene_name}/{cname}"
            base = dict(config=key, width=args.width, height=args.height)
            passes = [k for k in runs if ":" not in k]
            recs, rows = [], {}
            for name in passes:
                p = {**base, "pass": name}
                recs.append(bench.record(p, "ms", "ms", runs[name]))
                rows[name] = dict(ms=float(np.median(runs[name])))
                w = work_of(name, s, stats, tuple(passes))
                if w is None or name == "total" or np.median(runs[name]) <= 0:
                    continue
                f, rd, wr, bound = w
                recs += [bench.record(p, "fetches", "fetches", [f]), bench.record(p, "bytes_read", "B", [rd]),
                         bench.record(p, "bytes_written", "B", [wr])]
                rate = [f / (m * 1e-3) for m in runs[name]]
                recs.append(bench.record(p, "rate", "Gfetch/s", [v / 1e9 for v in rate], better="higher"))
                share = bench.record(p, "share_of_peak", "share", [v / peaks[bound]["rate"] for v in rate],
                                     better="higher", bound=bound)
                recs.append(share)
                if bound == "dependent":
                    recs.append(bench.record(p, "share_of_dependent_image", "share",
                                             [v / peaks["dependent_image"]["rate"] for v in rate], better="higher"))
                rows[name].update(fetches=f, rate=float(np.median(rate)), share=float(np.median(share["samples"])),
                                  bound=bound)
            cpu = {k: bench.record({**base, "side": "cpu"}, k.split(":")[1], "ms", runs[k])
                   for k in ("cpu:wall", "cpu:readback")}
            overhead = [a - b for a, b in zip(runs["cpu:wall"], runs["total"])]
            bench.record({**base, "side": "cpu"}, "overhead", "ms", overhead)
            px = s.width * s.height
            for k in ("peak:copy", "peak:copy_image", "peak:dependent", "peak:dependent_image"):
                bench.record({**base, "side": "interleaved peak", "pass": k.split(":")[1]}, "ms", "ms", runs[k])
            print(f"\n{key} ({', '.join(f'{k}={v}' for k, v in kw.items())}); share_of_peak: of the peak named by "
                  f"the record's bound")
            bench.print_table(recs, rows=("pass",), order=["ms", "fetches", "bytes_read", "bytes_written", "rate",
                                                           "share_of_peak", "share_of_dependent_image"], digits=3)
            print(f"render() + frame.color wall {records.cell(cpu['cpu:wall']['samples'], 1)} ms, CPU-side overhead "
                  f"over the GPU total {records.cell(overhead, 1)} ms, color readback "
                  f"{records.cell(cpu['cpu:readback']['samples'], 1)} ms")
            result["configs"][key] = dict(passes=rows, stats=stats)
            each[key] = dict(runs=runs, px=px)

    ratios = {}  # key -> every round's value
    for key, cfg in result["configs"].items():
        p, e = cfg["passes"], each[key]["runs"]
        px = each[key]["px"]
        if "composite" in e:
            ratios[f"{key}: composite / copy"] = paired(e["composite"], e["peak:copy"])
            # The same against a copy that reads by imageLoad, as the composite does on the CPU
            # device (input_fetch): no target (the copy pass reads by texelFetch).
            ratios[f"{key}: composite / copy by imageLoad"] = paired(e["composite"], e["peak:copy_image"])
        if "fetches" in p.get("trace_hiz", {}):
            # (fetches / trace time) / (the dependent kernel's fetches / its time), round by round
            ratios[f"{key}: trace_hiz share of dependent-fetch rate"] = [
                p["trace_hiz"]["fetches"] / (px * 64) * dep / t for t, dep in zip(e["trace_hiz"], e["peak:dependent"])]
            # The same against the imageLoad chain, the faster of the two on llvmpipe and the path
            # the trace reads its pyramid by there: no target (the peak is texelFetch's).
            ratios[f"{key}: trace_hiz share of the dependent imageLoad rate"] = [
                p["trace_hiz"]["fetches"] / (px * 64) * dep / t
                for t, dep in zip(e["trace_hiz"], e["peak:dependent_image"])]
        if "trace_hiz" in e and "resolve" in e:
            ratios[f"{key}: resolve / trace_hiz"] = paired(e["resolve"], e["trace_hiz"])
    if args.baseline:
        base = json.loads(Path(args.baseline).read_text())
        for scene_name in args.scenes:
            b = base.get(scene_name)
            cur = each.get(f"{scene_name}/thesis")
            if b and cur:
                ratios[f"{scene_name}/thesis: baseline / now (frame speed-up)"] = [b / v for v in cur["runs"]["total"]]
    if args.baseline_shaders:
        print(f"\nagainst the shaders in {args.baseline_shaders} (frames interleaved, this run)")
        before = ssrlab.Renderer(args.device, shader_dir=args.baseline_shaders)
        for scene_name in args.scenes:
            scene = getattr(ssrlab.scenes, scene_name)()
            for cname, kw in configs.items():
                s = ssrlab.Settings(width=args.width, height=args.height, **kw)
                ab_shaders(bench, before, renderer, scene, s, f"{scene_name}/{cname}", ratios)
    targets = {"composite / copy": ("<=", 2.0), "resolve / trace_hiz": ("<=", 0.6),
               "share of dependent-fetch rate": (">=", 0.25), "speed-up": (">=", 2.0)}
    print("\nratios, one per round (the targets' verdicts from the rounds' middle half)")
    rows = []
    for k, values in ratios.items():
        rec = bench.record(dict(ratio=k, width=args.width, height=args.height), "ratio", "x", values)
        result["ratios"][k] = float(np.median(values))
        result["ratio_repeats"][k] = [float(x) for x in values]
        # The targets are set against its texelFetch kernels; the imageLoad ratios have none.
        op, goal = next((t for name, t in targets.items() if name in k and "imageLoad" not in k), ("", None))
        rows.append([k, records.cell(rec["samples"], 3), "" if goal is None else f"{op} {goal:g}",
                     "" if goal is None else goal_verdict(values, op, goal)])
    print(records.markdown(["ratio", "median [25th-75th percentile]", "target", "verdict"], rows))
    bad = [k for k, v in result["ratios"].items() if not math.isfinite(v)]
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1, default=float))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
