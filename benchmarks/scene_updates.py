"""What a frame costs after the scene changed: a moved object or an edited material against a
still frame, and the BVH's update against the triangles that moved.

    python benchmarks/scene_updates.py [--width 320 --height 180 --layers 4] [--repeats 9] [--suzannes 100]

The scene: `hall` with --suzannes copies of Blender's Suzanne (the sample model, 3,936 triangles
each) in a grid over its floor: 394 k triangles with 100.

Frames (Settings: the image size, --layers, everything else the defaults): per repeat, in turn,
  still     a render of the unchanged scene,
  moved     a render after Scene.set_object_transform of one Suzanne (between two places inside
            the hall, so the scene's bounds and the lights' frusta stay),
  material  a render after Scene.set_material of one Suzanne (its roughness and colour),
each timed on the wall clock around Renderer.render and reading frame.color back (what a program
pays per frame), with the GPU total (Frame.timings["total"]) beside it; after one untimed pass over
the cases (compilation, uploads, the deep G-buffer's 'auto' measurement). Printed: median [min - max]
(interquartile range) of each, and the median of the per-repeat ratios to the still frame of the
same repeat (the shared machine's load drifts between repeats; a ratio within a repeat does not).
The same with method "bvh" (the moved frame pays the BVH update of the moved triangles).

BVH update against moved triangles: with method "bvh" (and, in a second table, with the Embree
scene of the CPU reference built too, which follows the same objects), k Suzannes are moved before
a render; Renderer.stats bvh_update_ms (the update's wall time: the moved objects' trees rebuilt,
the top tree, the uploads of what changed, Embree's commit) and bvh_update_last_triangles, median
[min - max] over the repeats. The last row moves every object (hall's too): the whole BVH rebuilt
object by object, against which the rows compare. These frames are 64x36 (the update does not
depend on the image; small frames keep the benchmark short).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import benchmark_arguments, open_renderer  # noqa: E402


def suzanne_hall(count: int):
    """hall with `count` Suzannes in rows of 10 over its floor; returns (scene, their object ids)."""
    import ssrlab
    from ssrlab import transforms as T

    scene = ssrlab.scenes.hall()
    path = ssrlab.models.find("Suzanne")
    ids = []
    for i in range(count):
        x, z = -3.6 + 0.8 * (i % 10), -2.0 - 2.0 * (i // 10)
        ids += scene.add_gltf(path, T.translate((x, 1.2, z)) @ T.scale(0.35))
    scene.name = f"hall + {count} Suzannes"
    return scene, ids


def place(home, obj, k):
    """One of two places of `obj` (its transform in `home`, moved on odd k), inside the hall."""
    from ssrlab import transforms as T

    return T.translate((0.2 * (k % 2), 0.15 * (k % 2), 0.0)) @ home[obj]


def fmt(values, unit=""):
    from ssrlab.lab.timing import spread

    st = spread(values)
    return f"{st['median']:8.1f}{unit} [{st['min']:.1f} - {st['max']:.1f}] ({st['iqr']:.1f})"


def time_frames(r, scene, home, ids, settings, repeats):
    """{case: [(wall ms, GPU ms)]} of still, moved and material frames, interleaved."""
    import ssrlab

    mover, painted = ids[len(ids) // 2], ids[len(ids) // 2 + 1]
    base = scene.material(painted)

    def frame():
        t = time.perf_counter()
        f = r.render(scene, settings=settings)
        _ = f.color
        wall = (time.perf_counter() - t) * 1e3
        return wall, f.timings["total"], f

    def change(case, k):
        if case == "moved":
            scene.set_object_transform(mover, place(home, mover, k))
        elif case == "material":
            m = ssrlab.Material(base_color=(0.3 + 0.4 * (k % 2), 0.4, 0.5, 1.0), roughness=0.2 + 0.3 * (k % 2),
                                metallic=base.metallic, reflectivity=base.reflectivity)
            scene.set_material(painted, m)

    out = {c: [] for c in ("still", "moved", "material")}
    stats = {c: [] for c in out}
    for k in range(repeats + 1):
        for case in out:
            change(case, k)
            wall, gpu, f = frame()
            if k > 0:  # k == 0 pays compilation, uploads, 'auto' measurements
                out[case].append((wall, gpu))
                stats[case].append(dict(f.stats))
    return out, stats


def print_frames(title, out, stats):
    print(title)
    still = [w for w, _ in out["still"]]
    for case, rows in out.items():
        wall, gpu = [w for w, _ in rows], [g for _, g in rows]
        ratio = np.median([w / s for w, s in zip(wall, still)])
        extra = ""
        if "shadow_maps_reused" in stats[case][0]:
            st = stats[case][-1]
            extra = (f"   shadow maps reused {st['shadow_maps_reused']:.0f} updated {st['shadow_maps_updated']:.0f} "
                     f"drawn {st['shadow_maps_rendered']:.0f}")
        print(f"  {case:9s} wall ms {fmt(wall)}   GPU ms {fmt(gpu)}   / still {ratio:.3f}{extra}")


def time_bvh_updates(r, scene, home, ids, settings, counts, repeats):
    """[(k, triangles, [update ms])] for k moved Suzannes (and every object last)."""
    rows = []
    everything = list(range(scene.object_count))
    for k in [*counts, len(everything)]:
        movers = everything if k == len(everything) else ids[:k]
        times, tris = [], 0
        for rep in range(repeats + 1):
            for obj in movers:
                scene.set_object_transform(obj, place(home, obj, rep + 1))
            before = r.stats["bvh_updates"]
            r.render(scene, settings=settings)
            st = r.stats
            assert st["bvh_updates"] == before + 1, "a render after a move updates the BVH once"
            if rep > 0:
                times.append(st["bvh_update_ms"])
            tris = int(st["bvh_update_last_triangles"])
        rows.append((len(movers), tris, times))
        for obj in movers:  # back home
            scene.set_object_transform(obj, home[obj])
    return rows


def print_bvh(title, rows):
    print(title)
    full = np.median(rows[-1][2])
    for k, tris, times in rows:
        what = "every object" if k == rows[-1][0] else f"{k:3d} Suzanne{'s' if k > 1 else ' '}"
        print(f"  {what:13s} {tris:8d} triangles: {fmt(times, ' ms')}   / all {np.median(times) / full:.3f}")


def main(argv=None) -> int:
    ap = benchmark_arguments(__doc__, repeats=9)
    ap.set_defaults(width=320, height=180)
    ap.add_argument("--layers", type=int, default=4)
    ap.add_argument("--suzannes", type=int, default=100)
    ap.add_argument("--moved", type=int, nargs="+", default=[1, 2, 5, 10, 25, 50, 100],
                    help="Suzannes moved per BVH update")
    args = ap.parse_args(argv)
    import ssrlab

    r = open_renderer(args)
    scene, ids = suzanne_hall(args.suzannes)
    home = {i: scene.object_transform(i) for i in range(scene.object_count)}
    settings = ssrlab.Settings(width=args.width, height=args.height, layers=args.layers)
    print(f"{scene.name}: {scene.triangle_count} triangles, {scene.object_count} objects; "
          f"{args.width}x{args.height}, {args.layers} layers; {args.repeats} repeats after one untimed pass over the cases")
    print_frames("frames (ms: median [min - max] (iqr); / still: median of the per-repeat ratios):",
                 *time_frames(r, scene, home, ids, settings, args.repeats))
    bvh = settings.replace(method="bvh")
    print_frames('frames with method "bvh":', *time_frames(r, scene, home, ids, bvh, args.repeats))
    counts = [k for k in args.moved if k <= len(ids)]
    bvh = bvh.replace(width=64, height=36)
    print_bvh('BVH update after moving k Suzannes (method "bvh"), ms:',
              time_bvh_updates(r, scene, home, ids, bvh, counts, args.repeats))
    f = r.render(scene, settings=bvh)
    f.reference("converged", rays=1, tracer="cpu")  # Embree's scene of the CPU reference, kept from now on
    print_bvh("the same with the CPU reference's Embree scene built (it follows the moved objects too), ms:",
              time_bvh_updates(r, scene, home, ids, bvh, counts, args.repeats))
    return 0


if __name__ == "__main__":
    sys.exit(main())
