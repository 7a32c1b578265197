"""The device's floors under the deep G-buffer, on the scene's own triangles at the frame's size.

    python benchmarks/timing/raster_floor.py [--width 640 --height 360 --repeats 15 --scenes hall]
    python benchmarks/timing/raster_floor.py --device gpu --width 1920 --height 1080      (where a GPU is)

Renderer.raster_floor draws the scene with its own vertex and index buffers through the G-buffer's
vertex shader (passes/depth_peel.vert), by fragment stages that do nothing but write, and times
each floor by GPU timer queries: median [min - max] of `repeats` after one untimed run (shader
compilation and first use), the floors interleaved within each repeat so that a slow spell of a
shared machine falls on all of them alike. The floors:

  depth          a depth-only draw (the least each layer's geometry pass of peeling does)
  gbuffer        depth + sRGB RGBA8 + RGBA16F + RGBA8 through the raster outputs, constants
                 written (one G-buffer layer the way peeling writes it)
  id             depth + an R32UI triangle id (one layer of a visibility buffer)
  append         every fragment's 8 bytes (depth, id) into per-pixel arrays, no depth test
  append_list    the same into linked lists (12 bytes a fragment with the link, one global counter)
  stores         compute image stores of one layer's bytes (R32F, RGBA8, RGBA16F, RGBA8: 20 B a pixel)
  clear.*        framebuffer clears of the depth and of the G-buffer's targets, compute clears of
                 the colour targets (the passes' clear_layers.comp) and of an R32UI target,
                 glClearTexImage of the R32UI target, the appends' per-pixel buffers cleared

Beside each: its rate (fragments and triangles a second for the draws, bytes a second for
full-frame writes), and the floors of one layer built each way. construction_floor() below is
what benchmarks/timing/deep_gbuffer.py compares each construction with. Each floor's repeats are a record
(ssrlab.lab.records).
"""

from __future__ import annotations

import sys
from pathlib import Path

import ssrlab

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab import records  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402

# (floor, what it is, bytes it writes per pixel of the frame: None for the draws, whose work is
# counted in fragments)
FLOORS = [
    ("depth", "depth-only draw", None),
    ("gbuffer", "depth + 3 colour targets through the raster outputs", None),
    ("id", "depth + R32UI triangle id", None),
    ("append", "every fragment's 8 B into per-pixel arrays", None),
    ("append_list", "every fragment into linked lists (12 B)", None),
    ("stores", "compute stores of one layer's 20 B a pixel", 20),
    ("clear.depth", "framebuffer clear of the depth", 4),
    ("clear.gbuffer", "framebuffer clear of depth + 3 colour targets", 20),
    ("clear.compute_colour", "compute clear of the 3 colour targets", 16),
    ("clear.id_texture", "glClearTexImage of the R32UI id", 4),
    ("clear.id_compute", "compute clear of the R32UI id", 4),
    ("clear.counters", "buffer clear of the per-pixel counters", 4),
    ("clear.heads", "buffer clear of the list heads (+ counter)", 4),
]

# What each construction of Settings.deep_gbuffer must do at least, in floors, for `layers` filled
# layers: the writes of its own structure at the device's floor, with none of its shading, tests
# or selection. A construction's time over this says how far it is from its floor on this device.
CONSTRUCTION_FLOORS = {
    # per layer one geometry pass writing the G-buffer's targets through the raster outputs, after
    # a framebuffer clear of them (peeling draws each layer twice: depth, then shading)
    "peel": ((), ("clear.gbuffer", "gbuffer")),
    # every fragment appended once (the 12-byte list, less than the 64 bytes it stores), then per
    # layer the G-buffer written back through the raster outputs (at least a clear's bytes)
    "lists": (("clear.heads", "append_list"), ("clear.gbuffer",)),
    # per layer a depth + id geometry pass after a depth clear, and the layer's attributes stored
    # by compute
    "visibility": ((), ("clear.depth", "id", "stores")),
    # every fragment's 8 bytes appended once, then per layer its attributes and its depth stored
    # by compute (the depth's 4 bytes are the stores' R32F)
    "visibility_lists": (("clear.counters", "append"), ("stores",)),
}


def construction_floor(method: str, layers: int, medians: dict[str, float]) -> float:
    """The floor of `method` building `layers` filled layers (CONSTRUCTION_FLOORS), in ms, from
    the floors' medians (or one repeat's times); NaN when a floor it needs was not measured."""
    once, per_layer = CONSTRUCTION_FLOORS[method]
    try:
        return sum(medians[f] for f in once) + max(layers, 1) * sum(medians[f] for f in per_layer)
    except KeyError:
        return float("nan")


def describe_floor(method: str) -> str:
    once, per_layer = CONSTRUCTION_FLOORS[method]
    return " + ".join(list(once) + [f"layers x ({' + '.join(per_layer)})"])


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=15)
    ap.set_defaults(scenes=["hall"])
    args = ap.parse_args()
    renderer = open_renderer(args)
    bench = Bench("raster_floor", args, renderer, warmup=1)
    print(f"{args.width}x{args.height}, {args.repeats} repeats after one untimed run, floors interleaved within each "
          f"repeat; GPU milliseconds (timer queries)\n")
    pixels = args.width * args.height
    for name in args.scenes:
        scene = ssrlab.scenes.load(str(ssrlab.models.find(name))) if name == "2CylinderEngine" else \
            ssrlab.scenes.load(name)
        f = renderer.raster_floor(scene, width=args.width, height=args.height, repeats=args.repeats)
        c = f.counts
        params = dict(scene=name, width=args.width, height=args.height)
        for key, samples in f.ms.items():  # each floor's repeats, the floors interleaved within each
            bench.record({**params, "floor": key}, "floor", "ms", samples)
        for key in ("fragments", "triangles", "max_fragments_per_pixel"):
            bench.record(params, key, "count", [c[key]])
        print(f"{name} ({c['triangles']} triangles): {c['fragments']} fragments "
              f"({c['fragments'] / pixels:.2f} a pixel, {c['max_fragments_per_pixel']} the deepest pixel), "
              f"{c['pixels_depth']} of {pixels} pixels covered, {c['samples_depth']} samples passed the depth "
              f"test (draws in the scene's order)")
        recs, missing = [], []
        for key, what, bytes_per_pixel in FLOORS:
            if key not in f.ms:
                missing.append(f"{key} ({what}): not measured (beyond the device's largest storage block)")
                continue
            p = {**params, "floor": key}
            ms = f.ms[key]
            recs.append(bench.find("floor", **params, floor=key)[0])
            if bytes_per_pixel is None:
                # every fragment the raster makes, every triangle the vertex stage takes
                recs.append(bench.record(p, "fragment_rate", "Mfrag/s", [c["fragments"] / v / 1e3 for v in ms],
                                         better="higher"))
                recs.append(bench.record(p, "triangle_rate", "Mtri/s", [c["triangles"] / v / 1e3 for v in ms],
                                         better="higher"))
            else:  # bytes / (ms / 1e3) / 1e9
                recs.append(bench.record(p, "bandwidth", "GB/s", [bytes_per_pixel * pixels / v / 1e6 for v in ms],
                                         better="higher"))
        bench.print_table(recs, rows=("floor",), digits=3)
        print(records.markdown(["floor", "what"], [[k, w] for k, w, _ in FLOORS if k in f.ms]))
        for line in missing:
            print(f"  {line}")
        medians = {k: f.median(k) for k in f.ms}
        print("one layer at the floor, each construction's way (benchmarks/timing/deep_gbuffer.py compares with these):")
        rows = [[method, f"{construction_floor(method, 1, medians):.3f}", describe_floor(method)]
                for method in CONSTRUCTION_FLOORS]
        print(records.markdown(["construction", "floor ms (of the floors' medians)", "sum of"], rows))
        print()


if __name__ == "__main__":
    main()
