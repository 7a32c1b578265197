"""What a frame costs after the scene changed: a moved object or an edited material against a
still frame, and the BVH's update against the triangles that moved.

    python benchmarks/timing/scene_updates.py [--width 320 --height 180 --layers 4] [--repeats 9] [--suzannes 100]

The scene: `hall` with --suzannes copies of Blender's Suzanne (the sample model, 3,936 triangles
each) in a grid over its floor: 394 k triangles with 100.

Frames (Settings: the image size, --layers, everything else the defaults): per repeat, in turn,
  still     a render of the unchanged scene,
  moved     a render after Scene.set_object_transform of one Suzanne (between two places inside
            the hall, so the scene's bounds and the lights' frusta stay),
  material  a render after Scene.set_material of one Suzanne (its roughness and colour),
each timed on the wall clock around Renderer.render and reading frame.color back (what a program
pays per frame), with the GPU total (Frame.timings["total"]) beside it; the protocol's rounds after
one untimed round over the cases (compilation, uploads, the deep G-buffer's 'auto' measurement).
Recorded, and printed in tables rendered from the records: each figure's samples, and each
round's ratio to the still frame of the same round (the shared machine's load drifts between
rounds; a ratio within a round does not).
The same with method "bvh" (the moved frame pays the BVH update of the moved triangles).

BVH update against moved triangles: with method "bvh" (and, in a second table, with the Embree
scene of the CPU reference built too, which follows the same objects), k Suzannes are moved before
a render; Renderer.stats bvh_update_ms (the update's wall time: the moved objects' trees rebuilt,
the top tree, the uploads of what changed, Embree's commit) and bvh_update_last_triangles, median
over the rounds (one untimed first). The last row moves every object (hall's too): the whole BVH rebuilt
object by object, against which the rows compare. These frames are 64x36 (the update does not
depend on the image; small frames keep the benchmark short).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path


sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402


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


def time_frames(bench, r, scene, home, ids, settings, params: dict) -> list[dict]:
    """Records the wall and GPU ms of still, moved and material frames, interleaved round by round
    (bench.rounds, one untimed round), with each round's wall ratio to its still frame; returns
    the records."""
    import ssrlab

    mover, painted = ids[len(ids) // 2], ids[len(ids) // 2 + 1]
    base = scene.material(painted)
    state = {"k": 0, "stats": {}}

    def change(case, k):
        if case == "moved":
            scene.set_object_transform(mover, place(home, mover, k))
        elif case == "material":
            m = ssrlab.Material(base_color=(0.3 + 0.4 * (k % 2), 0.4, 0.5, 1.0), roughness=0.2 + 0.3 * (k % 2),
                                metallic=base.metallic, reflectivity=base.reflectivity)
            scene.set_material(painted, m)

    def frame(case):
        def run():
            if case == "still":
                state["k"] += 1  # a new round: the moved and painted objects take their other place
            change(case, state["k"])
            t = time.perf_counter()
            f = r.render(scene, settings=settings)
            _ = f.color
            wall = (time.perf_counter() - t) * 1e3
            state["stats"][case] = dict(f.stats)
            return {"wall": wall, "gpu": f.timings["total"]}
        return run

    cases = ("still", "moved", "material")
    times = bench.rounds({c: frame(c) for c in cases}, warmup=1)
    out = []
    for case in cases:
        p = {**params, "case": case}
        out.append(bench.record(p, "wall", "ms", times[case]["wall"]))
        out.append(bench.record(p, "gpu_total", "ms", times[case]["gpu"]))
        out.append(bench.record(p, "wall_over_still", "x",
                                [a / b for a, b in zip(times[case]["wall"], times["still"]["wall"])]))
        st = state["stats"][case]
        for key in ("shadow_maps_reused", "shadow_maps_updated", "shadow_maps_rendered"):
            if key in st:
                out.append(bench.record(p, key, "maps", [st[key]]))
    return out


def time_bvh_updates(bench, r, scene, home, ids, settings, counts, params: dict) -> list[dict]:
    """Records the BVH update's ms (Renderer.stats bvh_update_ms) after moving k Suzannes (and
    every object last), bench's rounds with one untimed first; returns the records."""
    everything = list(range(scene.object_count))
    out = []
    for k in [*counts, len(everything)]:
        movers = everything if k == len(everything) else ids[:k]
        state = {"rep": 0, "tris": 0}

        def update():
            state["rep"] += 1
            for obj in movers:
                scene.set_object_transform(obj, place(home, obj, state["rep"]))
            before = r.stats["bvh_updates"]
            r.render(scene, settings=settings)
            st = r.stats
            assert st["bvh_updates"] == before + 1, "a render after a move updates the BVH once"
            state["tris"] = int(st["bvh_update_last_triangles"])
            return {"bvh_update": st["bvh_update_ms"]}

        times = bench.rounds({"update": update}, warmup=1)["update"]
        moved = "every object" if k == len(everything) else f"{k} Suzanne{'s' if k > 1 else ''}"
        out.append(bench.record({**params, "moved": moved, "triangles": state["tris"]}, "bvh_update", "ms",
                                times["bvh_update"]))
        for obj in movers:  # back home
            scene.set_object_transform(obj, home[obj])
    return out


def main(argv=None) -> int:
    ap = benchmark_arguments(__doc__, repeats=9)
    ap.set_defaults(width=320, height=180)
    ap.add_argument("--layers", type=int, default=4)
    ap.add_argument("--suzannes", type=int, default=100)
    ap.add_argument("--moved", type=int, nargs="+", default=[1, 2, 5, 10, 25, 50, 100],
                    help="Suzannes moved per BVH update")
    args = ap.parse_args(argv)
    import ssrlab

    from ssrlab.lab.protocol import Bench

    r = open_renderer(args)
    bench = Bench("scene_updates", args, r)
    scene, ids = suzanne_hall(args.suzannes)
    home = {i: scene.object_transform(i) for i in range(scene.object_count)}
    settings = ssrlab.Settings(width=args.width, height=args.height, layers=args.layers)
    print(f"{scene.name}: {scene.triangle_count} triangles, {scene.object_count} objects; "
          f"{args.width}x{args.height}, {args.layers} layers; {args.repeats} rounds after one untimed round over the cases")
    size = dict(width=args.width, height=args.height, layers=args.layers, suzannes=args.suzannes)
    frames = time_frames(bench, r, scene, home, ids, settings, {**size, "method": settings.method})
    frames += time_frames(bench, r, scene, home, ids, settings.replace(method="bvh"), {**size, "method": "bvh"})
    print("frames (wall_over_still: each round's wall ms over its still frame's):")
    bench.print_table(frames, rows=("method", "case"), digits=3)
    counts = [k for k in args.moved if k <= len(ids)]
    bvh = settings.replace(method="bvh", width=64, height=36)
    small = dict(width=64, height=36, layers=args.layers, suzannes=args.suzannes)
    updates = time_bvh_updates(bench, r, scene, home, ids, bvh, counts, {**small, "embree": False})
    f = r.render(scene, settings=bvh)
    f.reference("converged", rays=1, tracer="cpu")  # Embree's scene of the CPU reference, kept from now on
    updates += time_bvh_updates(bench, r, scene, home, ids, bvh, counts, {**small, "embree": True})
    print('\nBVH update after moving k Suzannes (method "bvh"; embree: with the CPU reference\'s Embree scene built, '
          'which follows the moved objects too):')
    bench.print_table(updates, rows=("embree", "moved", "triangles"), digits=3)
    return 0


if __name__ == "__main__":
    sys.exit(main())
