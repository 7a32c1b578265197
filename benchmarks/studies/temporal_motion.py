"""Temporal reflections on scenes where things move: per-frame error, ghosting and lag of each way to
reproject the history, and what moving one object costs.

    python benchmarks/studies/temporal_motion.py [--width 320 --height 180 --layers 4] [--frames 32 --moving 16]
        [--reference-rays 64] [--orbit 10] [--sequences ...] [--repeats 5 --suzannes 100] [--no-costs]

Sequences (ssrlab.lab.temporal.MOTION_SEQUENCES), each with a still camera and with a camera
orbiting its target by --orbit degrees over the frames: a sphere crossing a mirror floor, a long box
turning over a glossy floor (roughness 0.2), the animated glTF stage (ssrlab.lab.animated_gltf)
playing its "Spin" animation. Objects move over the first --moving frames, then stand still.

Configurations (1 ray per pixel, --layers layers, everything else the defaults): each frame alone;
the temporal accumulation (temporal_reflections) with the reflection reprojected by the surface
(reflection_reprojection="surface") or by the hit ("hit"), history rejected with or without the
layers (reject_layers), without and with the neighbourhood clamp (temporal_clamp=1, with the layers).

Per configuration, from ssrlab.lab.temporal.motion_study, against each frame's converged reference
(--reference-rays rays), rmse over the reflective pixels:
  err@K      the error at frame K = --moving (the last frame of the motion), and / single its ratio
             to the single frame's error at that frame (the same rays); still: the same ratio had
             the scene stood in frame K's pose (its final one) from the first frame, what the
             configuration reaches without motion;
  moved, disocc., rest   the mean error over the moving frames of the pixels whose reflection shows a
             moved object, of the pixels newly disoccluded, of the others;
  ghost      the error energy in the region the moving objects left (5x5-averaged error, summed over
             the region and the frames), and excess: its part above the single frame's (the trail
             the history adds);
  lag        frames after the motion stops until the error over the motion's footprint is within
             10 % of the level the same configuration converges to when the scene stands still
             (lag_beyond where it never was: the lag is beyond the frames the sequence had left).
The bound (ssrlab.lab.temporal.accumulation_bound): the per-pixel mean of K renders of frame K's
pose and camera, each alone with its own rays, against the same reference: what the best
accumulation of K frames reaches (no motion, no rejection, equal weights), so how much of the
single frame's error is noise that frames average out and how much is bias they all share.
Then the two claims for hit-point reprojection, per sequence: ghosting excess <= 0.25 x that of
surface-only reprojection (same rejection), and err@K <= 0.9 x the single frame's, with the bound
beside it: where the bound itself is above 0.9 x, no accumulation of K frames of that view can
meet that claim (frames of a moving camera see the scene from elsewhere: the `still` column says
what they reach).

Moving costs what moved (benchmarks/timing/scene_updates.py's measurement, its code): 100 Suzannes over
hall, a still frame against the frame after moving one Suzanne, and the BVH update of the moved
triangles (method "bvh", Renderer.stats bvh_update_ms), with the claim: moved frame <= 1.1 x the still
frame + the BVH update of one Suzanne.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402

from benchmarks.timing import scene_updates  # noqa: E402  (the still / moved frames and the BVH update, measured as it measures them)

GHOST_RATIO = 0.25  # hit-point reprojection's ghosting excess at most this share of surface-only's
ERROR_RATIO = 0.9   # its error after the motion at most this share of the single frame's
COST_RATIO = 1.1    # a frame after moving one object: at most this x a still frame + the BVH update


def configurations(base):
    from ssrlab.lab import temporal

    cfg = temporal.motion_configurations(base)
    cfg["surface + layers + clamp"] = cfg["surface + layers"].replace(temporal_clamp=1.0)
    cfg["hit + layers + clamp"] = cfg["hit + layers"].replace(temporal_clamp=1.0)
    return cfg


def excess(result, name):
    return float(result[name]["ghost"].sum() - result["single frame"]["ghost"].sum())


def record_study(bench, params, result, moving) -> list[dict]:
    """Records each configuration's figures of a motion study (the module notes): err@K, its ratio
    to the single frame's, the moving frames' errors by region (one sample per frame), the ghost
    energy and its excess over the single frame's, the lag and the still ratio; returns them."""
    k = moving - 1
    single = result["single frame"]["all"][k]
    out = []
    masks = result["masks"]
    for key, values in (("moved", masks["moved"][1:moving]), ("disoccluded", masks["disoccluded"][1:moving]),
                        ("ghost region", masks["ghost"][1:])):
        out.append(bench.record({**params, "configuration": "(pixels per frame)"}, f"{key} pixels", "pixels",
                                list(np.asarray(values, float))))
    for name in [n for n in result if isinstance(result[n], dict) and "all" in result[n]]:
        r = result[name]
        p = {**params, "configuration": name}
        window = slice(1, moving)
        out.append(bench.record(p, f"err@{moving}", "", [r["all"][k]]))
        out.append(bench.record(p, "over_single", "x", [r["all"][k] / single]))
        for region in ("moved", "disoccluded", "rest"):
            v = np.asarray(r[region][window], float)
            out.append(bench.record(p, region, "", list(v[np.isfinite(v)])))
        out.append(bench.record(p, "ghost", "", [float(r["ghost"].sum())]))
        out.append(bench.record(p, "excess", "", [excess(result, name) if name != "single frame" else 0.0]))
        if name != "single frame" and r["lag"] is not None:
            out.append(bench.record(p, "lag", "frames", [r["lag"]]))
        elif name != "single frame":
            # never within reach before the sequence ended: the lag is beyond the frames it had left
            out.append(bench.record(p, "lag_beyond", "frames", [result["frames"] - result["still_from"] - 1]))
        out.append(bench.record(p, "still", "x", [r["still at stop"] / single]))
    return out


def claims(result, moving, bound):
    """(ghost verdict line, error verdict line) of hit-point reprojection against surface-only; the
    error claim read against `bound` (temporal.accumulation_bound at the same frame)."""
    k = moving - 1
    single = result["single frame"]["all"][k]
    lines = []
    for rejection in ("", " + layers"):
        hit, surface = excess(result, "hit" + rejection), excess(result, "surface" + rejection)
        ok = hit <= GHOST_RATIO * surface if surface > 0 else hit <= 0
        ratio = f"{hit / surface:.3f}" if surface > 0 else "n/a (surface adds no ghost)"
        lines.append(f"  ghosting excess, hit{rejection} / surface{rejection}: {hit:+.3f} / {surface:+.3f} = {ratio} "
                     f"(<= {GHOST_RATIO}: {'yes' if ok else 'no'})")
    for name in ("hit", "hit + layers", "hit + layers + clamp"):
        e = result[name]["all"][k]
        lines.append(f"  error at frame {moving}, {name} / single frame: {e:.4f} / {single:.4f} = {e / single:.3f} "
                     f"(<= {ERROR_RATIO}: {'yes' if e <= ERROR_RATIO * single else 'no'})")
    # What no accumulation can beat: the mean of as many independent frames of that pose, still.
    attainable = bound["ratio"] <= ERROR_RATIO
    lines.append(f"  bound: the mean of {bound['count']} independent renders of frame {moving}'s pose, still: "
                 f"{bound['mean']:.4f} / {bound['single']:.4f} = {bound['ratio']:.3f} x single; "
                 + (f"<= {ERROR_RATIO} is within reach of an accumulation" if attainable else
                    f"<= {ERROR_RATIO} is out of reach of any accumulation of {bound['count']} frames of this view "
                    "(the rest of the error is screen space's bias, the same every frame; a moving camera's "
                    "frames see the scene from elsewhere, which the bound does not count: the still column)"))
    return lines


def costs(bench, renderer, args):
    """Moving costs what moved: scene_updates' still and moved frames and its BVH updates."""
    import ssrlab
    from ssrlab.lab.protocol import goal_verdict

    scene, ids = scene_updates.suzanne_hall(args.suzannes)
    home = {i: scene.object_transform(i) for i in range(scene.object_count)}
    settings = ssrlab.Settings(width=args.width, height=args.height, layers=args.layers)
    print(f"\nmoving costs what moved: {scene.name}, {scene.triangle_count} triangles, {args.width}x{args.height}, "
          f"{args.layers} layers; {args.repeats} rounds after one untimed round")
    size = dict(study="costs", width=args.width, height=args.height, layers=args.layers, suzannes=args.suzannes)
    frames = scene_updates.time_frames(bench, renderer, scene, home, ids, settings, size)
    bench.print_table(frames, rows=("case",), digits=3)
    bvh = settings.replace(method="bvh", width=64, height=36)
    renderer.render(scene, settings=bvh)  # builds the BVH: what follows updates it
    counts = [k for k in (1, 5, 25) if k <= len(ids)]
    rows = scene_updates.time_bvh_updates(bench, renderer, scene, home, ids, bvh, counts,
                                          {**size, "width": 64, "height": 36})
    print('BVH update after moving k Suzannes (method "bvh"):')
    bench.print_table(rows, rows=("moved", "triangles"), digits=3)
    still = [x for x in frames if x["metric"] == "wall" and x["params"]["case"] == "still"][0]["samples"]
    moved = [x for x in frames if x["metric"] == "wall" and x["params"]["case"] == "moved"][0]["samples"]
    update = float(np.median(rows[0]["samples"]))
    # one value per round: the moved frame over the same round's still frame plus the update's median
    ratio = [m / (COST_RATIO * s + update) for m, s in zip(moved, still)]
    print(f"  claim: moved frame <= {COST_RATIO} x still frame + BVH update of one Suzanne "
          f"({rows[0]['params']['triangles']} triangles), per round (wall clock): "
          f"{goal_verdict(ratio, '<=', 1.0)}")


def main(argv=None) -> int:
    ap = benchmark_arguments(__doc__, repeats=5)
    ap.set_defaults(width=320, height=180)
    ap.add_argument("--layers", type=int, default=4)
    ap.add_argument("--frames", type=int, default=32)
    ap.add_argument("--moving", type=int, default=16, help="frames over which the objects move")
    ap.add_argument("--reference-rays", type=int, default=64)
    ap.add_argument("--orbit", type=float, default=10.0, help="degrees the orbiting camera turns over the frames")
    ap.add_argument("--sequences", nargs="+", default=None, help="names of ssrlab.lab.temporal.MOTION_SEQUENCES")
    ap.add_argument("--suzannes", type=int, default=100)
    ap.add_argument("--no-costs", action="store_true", help="leave out the cost of moving one object")
    args = ap.parse_args(argv)
    import ssrlab
    from ssrlab.lab import temporal

    from ssrlab.lab.protocol import Bench

    r = open_renderer(args)
    bench = Bench("temporal_motion", args, r)
    print(time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()) +
          f"; {args.width}x{args.height}, {args.layers} layers, 1 ray per pixel, {args.frames} frames (objects move over "
          f"the first {args.moving}), converged references of {args.reference_rays} rays")
    base = ssrlab.Settings(width=args.width, height=args.height, layers=args.layers, rays_per_pixel=1)
    cfg = configurations(base)
    verdicts = []
    for name in args.sequences or list(temporal.MOTION_SEQUENCES):
        for orbit in (0.0, args.orbit):
            seq = temporal.MOTION_SEQUENCES[name](frames=args.frames, moving=args.moving, orbit_degrees=orbit)
            t = time.perf_counter()
            result = temporal.motion_study(r, seq, cfg, reference_rays=args.reference_rays)
            camera = "still camera" if orbit == 0.0 else f"camera orbiting {orbit:g} degrees"
            bound = temporal.accumulation_bound(r, seq, base, reference_rays=args.reference_rays)
            params = dict(sequence=name, camera=camera, width=args.width, height=args.height, layers=args.layers,
                          frames=args.frames, moving=args.moving, reference_rays=args.reference_rays)
            recs = record_study(bench, params, result, args.moving)
            print(f"\n{name}, {camera} ({time.perf_counter() - t:.0f} s):")
            pixels = [x for x in recs if x["params"]["configuration"] == "(pixels per frame)"]
            bench.print_table(pixels, rows=("configuration",), digits=0, note=False)
            bench.print_table([x for x in recs if x not in pixels], rows=("configuration",), digits=4)
            bench.record({**params, "configuration": "bound"}, f"err@{args.moving}", "", [bound["mean"]])
            bench.record({**params, "configuration": "bound"}, "over_single", "x", [bound["ratio"]])
            print(f"  bound: the mean of {bound['count']} independent renders of frame {args.moving}'s pose "
                  f"{bound['mean']:.4f} = {bound['ratio']:.3f} x single (an accumulation of {bound['count']} frames "
                  "does no better, up to the noise of one draw)")
            verdicts.append((f"{name}, {camera}", claims(result, args.moving, bound)))
    print("\nhit-point reprojection against surface-only reprojection:")
    for title, lines in verdicts:
        print(title)
        print("\n".join(lines))
    if not args.no_costs:
        costs(bench, r, args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
