"""Hybrid reflections (seed 004, thesis 4.3): accuracy and cost of SSR alone, SSR + reflection probes, SSR + BVH
fallback and pure BVH, and how often SSR's accepted hits are wrong.

    python benchmarks/studies/hybrid.py [--width 640 --height 360 --scenes hall hall_floor60 spheres_and_boxes
                                 --repeats 5]
    python benchmarks/studies/hybrid.py --sizes 160x90,320x180,640x360,1280x720

--sizes: for each size and each mirror-floor view (both hall views and crosscheck, the Mitsuba
cross-check's scene: ssrlab.crosscheck.crosscheck_scene(0)), the floor pixels' reflection PSNR
of SSR alone, SSR + BVH fallback and pure BVH, each with the BVH passes' shadows traced (the
default) and from the frame's shadow map (bvh_shadows="map"), against two named references:
"frame's shadows" (the converged reference with shadows="map": the frame's own shadow map,
viewed from the ray) and "physical" (shadows="traced", viewed from the ray: the one Mitsuba 3
agrees with, benchmarks/accuracy/mitsuba_crosscheck.py), with each frame's GPU time (median [min, max]
of --repeats renders after 2 warm-ups) and the shadow map variant's time over the default's.
The goal for SSR + fallback at default settings against the physical reference is 40 dB at
every size and view; the verdict is printed.

Views: `hall` (mirror floor, floor_roughness=0) from its default camera, whose floor reflections
leave the top of the screen; `hall_floor60`, the same hall from a camera looking down at the floor
at 60 degrees below the horizontal (position (0, 5, 1), direction (0, -sin 60, -cos 60): toward -z,
the nave's length; fov_y 60, so the floor fills the image and its reflections climb steeply past
the columns, capitals and beams into the open roof); `spheres_and_boxes` as built (1 glossy ray).

For each view, prints for SSR alone (fallback "environment"), SSR + probes (fallback "probes":
the default single probe at the scene bounds' centre, and a probe placed by hand near the camera,
low over the floor), SSR + BVH fallback with and without the confidence test, and pure BVH
(method "bvh"): the reflection's PSNR against the converged physical reference (viewer "ray",
shadows "traced": the shading the BVH passes use by default, bvh_shadows="traced", so that only
what each method finds differs), on reflective pixels and, for hall, on floor pixels; the thesis error E on reflective
pixels; where the rays were resolved (frame.fallback_stats); the share of SSR's accepted hits that
are wrong against the per-ray reference (ssrlab.reference.wrong_hits: another surface, or more than
2 px from the true hit; after the confidence test where it runs); and the median GPU time of the
frame and of its tracing and fallback passes over --repeats renders after warm-up. The probes'
one-time capture is printed apart (it is never in a frame's timings). All methods use origin_bias
0.0005 (see README). Every figure is a record (ssrlab.lab.records) with its samples.
"""

from __future__ import annotations

import sys
from pathlib import Path
import math

import numpy as np

import ssrlab
from ssrlab.metrics import psnr, thesis_error
from ssrlab.reference import wrong_hits

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import HYBRID_FRAMES, benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402
from ssrlab.lab import records  # noqa: E402

NEAR_PROBE = (0.0, 0.5, 1.5)  # hall: low over the floor, near the camera (both views)
CONFIGS = {
    "SSR only (linear)": dict(fallback="environment"),
    "SSR + probes (centre)": dict(fallback="probes"),
    "SSR + probes (near the camera)": dict(fallback="probes", _probes=[NEAR_PROBE]),
    "SSR + BVH fallback": dict(fallback="bvh"),
    "SSR + BVH fallback, no confidence": dict(fallback="bvh", fallback_confidence=False),
    "pure BVH": dict(method="bvh"),
}
TRACE_PASSES = ("trace_linear", "trace_hiz", "trace_bvh", "fallback_bvh", "fallback_probes")


def floor60_camera() -> ssrlab.Camera:
    pos = np.array([0.0, 5.0, 1.0])
    a = math.radians(60.0)
    target = pos + 6.0 * np.array([0.0, -math.sin(a), -math.cos(a)])
    return ssrlab.Camera(position=tuple(pos), target=tuple(target), fov_y=60.0, near=0.1, far=80.0)


def load(name: str) -> ssrlab.Scene:
    if name == "crosscheck":
        from ssrlab.crosscheck import crosscheck_scene

        return crosscheck_scene(0.0)
    if name in ("hall", "hall_floor60"):
        scene = ssrlab.scenes.hall(floor_roughness=0.0)
        if name == "hall_floor60":
            scene.camera = floor60_camera()
        return scene
    return ssrlab.scenes.load(name)


SIZE_VIEWS = ("hall", "hall_floor60", "crosscheck")
GOAL_DB = 40.0


def timed(bench, r, scene, settings, params) -> dict[str, list[float]]:
    """Every pass's GPU ms over the protocol's rounds (2 warm-ups), the frame's and the tracing
    and fallback passes' recorded."""
    t = bench.frames(r, scene, {"x": settings})["x"]
    trace = [sum(t[p][i] for p in TRACE_PASSES if p in t) for i in range(len(t["total"]))]
    bench.record(params, "frame", "ms", t["total"])
    bench.record(params, "trace", "ms", trace)
    return {**t, "trace": trace}


def sizes_table(r, sizes: list[tuple[int, int]], repeats: int, bench) -> None:
    """The hybrid's floor accuracy at every size against both named references, and each frame's time."""
    print(f"floor pixels' reflection PSNR (dB) against two converged references: 'frame's shadows' "
          f"(shadows='map') and 'physical' (shadows='traced'), both viewed from the ray; default settings "
          f"(origin_bias 0.0005) but for the row's; GPU ms of {repeats} rounds after {bench.warmup} warm-up "
          f"rounds\n")
    verdicts = []
    for name in SIZE_VIEWS:
        scene = load(name)
        for w, h in sizes:
            base = ssrlab.Settings(width=w, height=h, origin_bias=0.0005)
            f = r.render(scene, settings=base)
            floor = f.gbuffer.object_id[0] == 0
            refs = {"frame's shadows": f.reference("converged", rays=1, shadows="map").reflection.copy(),
                    "physical": f.reference("converged", rays=1, shadows="traced").reflection.copy()}
            print(f"{name} {w}x{h}: {int(floor.sum())} floor pixels")
            recs = []
            for label, kw in HYBRID_FRAMES.items():
                st = base.replace(**kw)
                g = r.render(scene, settings=st)
                scores = {k: psnr(g.reflection, t, mask=floor) for k, t in refs.items()}
                params = dict(view=name, width=w, height=h, method=label)
                for k, v in scores.items():
                    bench.record({**params, "reference": k}, "floor_psnr", "dB", [v], better="higher")
                    # the same figure under the table's column name
                    recs.append({**bench.find("floor_psnr", **params, reference=k)[0], "metric": f"vs {k}"})
                timed(bench, r, scene, st, params)
                recs += bench.find("frame", **params)
                if label == "SSR + BVH fallback":
                    verdicts.append((name, w, h, scores["physical"]))
            print(records.table(recs, ["method"], "metric", digits=2))
    worst = min(verdicts, key=lambda v: v[3])
    met = all(v[3] >= GOAL_DB for v in verdicts)
    print(f"SSR + BVH fallback (default settings) against the physical reference: lowest {worst[3]:.2f} dB "
          f"({worst[0]} {worst[1]}x{worst[2]}); goal >= {GOAL_DB:.0f} dB at every size and view: "
          f"{'met' if met else 'NOT met'}")


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=5)
    ap.add_argument("--sizes", help="comma-separated WxH list: the accuracy-at-every-size table (hall views)")
    ap.set_defaults(scenes=["hall", "hall_floor60", "spheres_and_boxes"])
    ap.add_argument("--reference-rays", type=int, default=64, help="converged reference rays per glossy pixel")
    args = ap.parse_args()
    r = open_renderer(args)
    bench = Bench("hybrid", args, r)
    if args.sizes:
        sizes = [tuple(int(x) for x in s.lower().split("x")) for s in args.sizes.split(",")]
        sizes_table(r, sizes, args.repeats, bench)
        return
    print(f"{args.width}x{args.height}, GPU ms of {args.repeats} rounds after {bench.warmup} warm-up rounds\n")
    for name in args.scenes:
        scene = load(name)
        hall = name.startswith("hall")
        base = ssrlab.Settings(width=args.width, height=args.height, origin_bias=0.0005)
        f = r.render(scene, settings=base)
        ref = f.reference("converged", rays=args.reference_rays)
        truth = ref.reflection[..., :3]
        masks = {"reflective": ref.reflective}
        if hall:
            masks["floor"] = f.gbuffer.object_id[0] == 0
        print(f"{name}" + (" (mirror floor)" if hall else "") + f": {int(ref.reflective.sum())} reflective pixels")
        captures, table = [], []
        for label, kw in CONFIGS.items():
            kw = dict(kw)
            probes = kw.pop("_probes", None)
            if probes is not None and not hall:
                continue
            sc = scene
            if probes is not None:
                sc = scene.copy()
                sc.probes = probes
            st = base.replace(**kw)
            g = r.render(sc, settings=st)
            if "probe_capture_ms" in g.stats:
                # A second capture of the same probes (a copy of the scene): the first one also
                # paid the capture shader's first-dispatch compilation.
                again = sc.copy()
                captures.append((label, int(g.stats["probes"]), r.render(again, settings=st).stats["probe_capture_ms"]))
            refl = g.reflection[..., :3]
            s = g.fallback_stats
            wrong = wrong_hits(g, g.reference("per_ray"), tolerance_px=2.0) \
                if st.method != "bvh" else None
            params = dict(view=name, width=args.width, height=args.height, method=label)
            for k, m in masks.items():
                bench.record({**params, "pixels": k}, "psnr", "dB", [psnr(refl, truth, mask=m)], better="higher")
            bench.record(params, "thesis_error", "", [thesis_error(refl, truth, masks["reflective"])])
            if wrong:
                bench.record(params, "wrong_hits", "share", [wrong["wrong_share"]])
            for k in ("screen", "probes", "bvh", "environment", "rejected"):
                bench.record(params, f"share_{k}", "share", [s[k]])
            timed(bench, r, sc, st, params)
            mine = bench.find(None, **params)
            cells = [records.cell(next(x["samples"] for x in mine if x["params"].get("pixels") == k), 2) + " dB"
                     for k in masks]
            one = {x["metric"]: x["samples"] for x in mine if "pixels" not in x["params"]}
            table.append([label, *cells, records.cell(one["thesis_error"], 4),
                          *(records.cell(one[f"share_{k}"], 2) for k in ("screen", "probes", "bvh", "environment",
                                                                        "rejected")),
                          records.cell([100 * v for v in one["wrong_hits"]], 2) + " %" if "wrong_hits" in one else "-",
                          records.cell(one["frame"], 1), records.cell(one["trace"], 1)])
        print(records.markdown(["method", *(f"PSNR {k}" for k in masks), "E refl.", "screen", "probe", "bvh", "env",
                                "rej.", "wrong", "frame ms", "trace ms"], table))
        for label, n, ms in captures:
            print(f"  probe capture ({label}): {n} probe(s) of 6 x {base.probe_size}^2 texels, {ms:.1f} ms once "
                  "(wall clock around the finished GPU work, cached until the scene or probe set changes)")
        print()


if __name__ == "__main__":
    main()
