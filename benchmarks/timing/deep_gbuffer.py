"""The deep G-buffer's construction: time and memory against layers, per method, beside its floor.

    python benchmarks/timing/deep_gbuffer.py [--width 640 --height 360 --repeats 7 --layers 1 2 4 8 16
                                       --methods peel lists visibility visibility_lists]

For hall, spheres_and_boxes, box_stack and the 2CylinderEngine sample model (skipped when not
found), builds the layered G-buffer with each exact construction of Settings.deep_gbuffer at each
layer count:
  peel              depth peeling: two geometry passes per layer (depth, then shading), seed 000 1.5.1
  lists             one geometry pass shading every fragment into per-pixel lists (64 bytes each),
                    a selection, the kept layers written back (Yang et al. 2010)
  visibility        peeling that rasterises depth and a triangle id only, then one compute pass
                    rebuilding every attribute of every kept sample (Burns and Hunt 2013)
  visibility_lists  one geometry pass appending (depth, id) per fragment (12 bytes with the link),
                    a selection storing ids and depths, the same attribute pass
and prints the GPU time of the construction (Frame.timings['deep_gbuffer']: median and the spread
min-max over `repeats` renders, after 2 warm-up renders), its ratio to ONE peeled layer of the
same scene measured in the same run, its parts, the lists' fragment count, the extra memory each
method takes beside the G-buffer textures every method writes (peel: its previous-layer depth copy;
lists: fragment store, heads, selection, and the copy; visibility: the copy and the R32UI ids per
layer, and on the CPU device with more than one layer, or with textured materials, the attribute
pass's binned samples, 12 bytes each, and its triangles' records, 80 bytes each where it keeps them;
visibility_lists: the same and its lists), the CPU time this
process spent in the render call with its ratio to the 1-layer peeled frame's (on llvmpipe the
work its threads did: the GPU timer measures wall time, which other jobs on a shared machine
inflate), and the construction's distance from its floor on this device.

The floor (benchmarks/timing/raster_floor.py, Renderer.raster_floor): what each construction must do at
least, at the device's floors on the scene's own triangles at the frame's size, for the layers
it filled (CONSTRUCTION_FLOORS there):
  peel              per layer a framebuffer clear of the G-buffer's targets and one geometry pass
                    writing depth and three colour targets through the raster outputs
  lists             every fragment appended once to linked lists (12 bytes), and per layer the
                    G-buffer's bytes written back through the raster outputs (a clear's)
  visibility        per layer a depth clear and a depth + id geometry pass, and the layer's
                    attributes stored by compute
  visibility_lists  every fragment's 8 bytes appended once to per-pixel arrays, and per layer its
                    depth and attributes stored by compute
None of it shades a material, tests a peel, selects or sorts: `x floor` is how much more than
its own unavoidable raster and memory work each construction spends. The floors draw and write
the full frame; on the CPU device peeling and the visibility buffer rasterise a deeper layer only
over the previous layer's covered tiles, so there a construction can come under its floor (x
floor < 1) on scenes whose deeper layers cover little. The floors are measured in every round
(raster_floor with one repeat) and each round's render is set against its own round's floors.

Configurations and floors are interleaved round by round, so that a slow spell of a shared machine
falls on every configuration alike. The frames render the G-buffer and the lighting only (method
'off', no shadow map): the other passes do not depend on how the layers were built.

Goals (on llvmpipe at 640x360), each against the device's own floor measured in the same round:
8 layers in at most 2x the construction's floor on hall, spheres_and_boxes and 2CylinderEngine,
and each visibility construction's single layer within 2x its floor. A ratio to the floor travels
between machines of a kind; a ratio to another configuration (one peeled layer) does not always,
so those are printed beside the goals and not judged. Each goal is judged on the rounds' ratios
(each from two measurements of the same round): "met" where the middle half of them (25th-75th
percentile) meets the goal, "not met" where it misses it, else "undecided at this noise". Every
figure is a record (ssrlab.lab.records) with one sample per round: the construction's ms, its
floor's, x floor (the goals' ratio), x one peeled layer and the CPU ms.
"""

from __future__ import annotations

import sys
from pathlib import Path
import statistics
import time

import numpy as np

import ssrlab

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402
from benchmarks.timing.raster_floor import construction_floor, describe_floor  # noqa: E402
from ssrlab.lab import records  # noqa: E402
from ssrlab.lab.protocol import Bench, goal_verdict  # noqa: E402

METHODS = ("peel", "lists", "visibility", "visibility_lists")
# Each method's parts (Frame.timings keys) and the short names they are printed under.
PARTS = {
    "peel": (("depth", "depth_peel.depth"), ("shade", "depth_peel.shade"), ("setup", "depth_peel.setup")),
    "lists": (("append", "fragment_lists.append"), ("select", "fragment_lists.select"),
              ("write", "fragment_lists.write")),
    "visibility": (("raster", "visibility_buffer"), ("triangles", "gbuffer_attributes.triangles"),
                   ("classify", "gbuffer_attributes.classify"),
                   ("bin", "gbuffer_attributes.bin"), ("shade", "gbuffer_attributes.shade"),
                   ("regions", "gbuffer_attributes.regions")),
    "visibility_lists": (("append", "visibility_buffer.append"), ("select", "visibility_buffer.select"),
                         ("triangles", "gbuffer_attributes.triangles"), ("classify", "gbuffer_attributes.classify"),
                         ("bin", "gbuffer_attributes.bin"), ("shade", "gbuffer_attributes.shade"),
                         ("regions", "gbuffer_attributes.regions")),
}
# The construction's time over its own floor (raster_floor.construction_floor) at 8 layers, on the
# scenes with a goal, and a visibility construction's at 1 layer.
GOAL_SCENES = ("hall", "spheres_and_boxes", "2CylinderEngine")
EIGHT_LAYER_GOAL = 2.0
ONE_LAYER_GOAL = 2.0
GOAL_DEVICE, GOAL_SIZE = "cpu", (640, 360)


def load(name: str):
    if name == "2CylinderEngine":
        try:
            return ssrlab.scenes.load(str(ssrlab.models.find(name)))
        except Exception as e:  # a missing sample model skips its rows, and says why
            print(f"{name}: skipped ({e})")
            return None
    return ssrlab.scenes.load(name)


def textured(scene) -> bool:
    """Whether some material has a texture (the attribute pass then bins its samples)."""
    return any(getattr(scene.material(i), t) >= 0 for i in range(scene.object_count)
               for t in ("base_color_texture", "metallic_roughness_texture", "normal_texture", "emissive_texture",
                         "specular_texture", "specular_color_texture"))


def extra_bytes(method: str, stats: dict, width: int, height: int, layers: int, binned: bool) -> int:
    """The memory the construction takes beside the G-buffer's textures (see the module notes)."""
    pixels = width * height
    used = int(stats.get("layers_used", layers))
    extra = 4 * pixels  # the previous layer's depth copy, declared by every construction
    built = stats.get("deep_gbuffer_method", method)
    if built in ("lists", "visibility_lists"):
        extra += int(stats.get("deep_gbuffer_bytes", 0))
    if method.startswith("visibility"):
        extra += 4 * pixels * layers  # gbuffer.visibility: a 32-bit id per sample
        if binned:
            extra += 12 * pixels * max(used, 1)  # the attribute pass's binned and sorted samples
        extra += 80 * int(stats.get("gbuffer_attributes_triangle_records", 0))  # its triangles' records
    return extra


def verdict(ratios: list[float], goal: float) -> str:
    """met / not met / undecided at this noise, from the rounds' ratios (the protocol's verdict)."""
    return goal_verdict(ratios, "<=", goal)


def quartiles(values) -> str:
    q1, q3 = np.percentile(values, [25, 75])
    return f"{statistics.median(values):.2f}x [{q1:.2f}-{q3:.2f}]"


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=7)
    ap.set_defaults(scenes=["hall", "spheres_and_boxes", "box_stack", "2CylinderEngine"])
    ap.add_argument("--layers", type=int, nargs="+", default=[1, 2, 4, 8, 16])
    ap.add_argument("--methods", nargs="+", default=list(METHODS), choices=METHODS)
    args = ap.parse_args()
    renderer = open_renderer(args)
    bench = Bench("deep_gbuffer", args, renderer)
    device = renderer.info["device"]
    print(f"{args.width}x{args.height}, median [25th-75th percentile] of {args.repeats} rounds after {bench.warmup} "
          f"warm-up rounds, "
          f"configurations and floors interleaved round by round; GPU milliseconds of the construction "
          f"(timings['deep_gbuffer']); x floor: the median of the rounds' construction / its floor "
          f"(benchmarks/timing/raster_floor.py) in the same round")
    print("floors: " + "; ".join(f"{m} = {describe_floor(m)}" for m in args.methods) + "\n")
    layer_counts = sorted(set(args.layers) | {1})
    methods = list(dict.fromkeys(["peel", *args.methods]))  # one peeled layer is every ratio's base
    summary = {}   # (scene, method, layers) -> rounds' ratios to one peeled layer
    distance = {}  # (scene, method, layers) -> (median x floor, floor ms)
    x_floor_rounds = {}  # (scene, method, layers) -> each round's time over that round's floor (the goals' ratio)
    built_as = {}  # (scene, method, layers) -> the method, and what it built where that differs
    shading_floors = []
    names = []
    for name in args.scenes:
        scene = load(name)
        if scene is None:
            continue
        names.append(name)
        configs = [(m, l) for m in methods for l in layer_counts if m in args.methods or l == 1]
        settings = {c: ssrlab.Settings(width=args.width, height=args.height, layers=c[1], deep_gbuffer=c[0],
                                       method="off", shadow_map_size=0) for c in configs}
        last = {"counts": {}, "stats": {}, "samples": {}}

        def floor_round():
            fl = renderer.raster_floor(scene, width=args.width, height=args.height, repeats=1)
            last["counts"] = fl.counts
            return {k: v[0] for k, v in fl.ms.items()}

        def render_round(c):
            def run():
                cpu0 = time.process_time()
                f = renderer.render(scene, settings=settings[c])
                out = {**f.timings, "cpu": 1000.0 * (time.process_time() - cpu0)}
                last["stats"][c] = dict(f.stats)
                last["samples"][c] = list(f.layer_samples)
                f.release()
                return out
            return run

        # the floors and every configuration interleaved round by round, after the warm-up rounds
        measured = bench.rounds({"floor": floor_round, **{c: render_round(c) for c in configs}})
        floor_keys = list(measured["floor"])
        floors = [{k: measured["floor"][k][i] for k in floor_keys} for i in range(bench.repeats)]
        counts, samples = last["counts"], last["samples"]
        cpu = {c: measured[c]["cpu"] for c in configs}
        times = {c: measured[c]["deep_gbuffer"] for c in configs}
        med = {c: statistics.median(times[c]) for c in configs}
        base_key = ("peel", 1)
        base = med[base_key]
        cpu_base = statistics.median(cpu[base_key])
        has_textures = textured(scene)
        floor_medians = {k: statistics.median(r[k] for r in floors) for k in floors[0]}
        print(f"{name} ({scene.triangle_count} triangles, {counts['fragments']} fragments, "
              f"{counts['max_fragments_per_pixel']} at the deepest pixel): 1 peeled layer = {base:.2f} ms")
        table = []
        for c in configs:
            method, layers = c
            ts = times[c]
            st = last["stats"][c]
            used = int(st["layers_used"])
            built = st.get("deep_gbuffer_method", method)
            how = method if built == method else f"{method}->{built}"
            built_as[(name, method, layers)] = how
            # The floor and the parts of what was built ('visibility_lists' at one layer, or lists
            # beyond their budget, are peeled).
            floor_of = built if built in METHODS else method
            floor_ms = construction_floor(floor_of, used, floor_medians)
            x_floor = statistics.median(t / construction_floor(floor_of, used, r) for t, r in zip(ts, floors))
            distance[(name, method, layers)] = (x_floor, floor_ms)
            x_floor_rounds[(name, method, layers)] = [t / construction_floor(floor_of, used, r)
                                                      for t, r in zip(ts, floors)]
            summary[(name, method, layers)] = [t / b for t, b in zip(ts, times[base_key])]
            params = dict(scene=name, method=method, built=built, layers=layers, used=used, width=args.width,
                          height=args.height)
            bench.record(params, "deep_gbuffer", "ms", ts)
            bench.record(params, "floor", "ms", [construction_floor(floor_of, used, r) for r in floors])
            # the goals' ratios, one per round: to the construction's floor, and to one peeled layer
            bench.record(params, "x_floor", "ratio", x_floor_rounds[(name, method, layers)])
            bench.record(params, "x_one_peeled_layer", "ratio", summary[(name, method, layers)])
            bench.record(params, "cpu", "ms", cpu[c])
            parts = " ".join(f"{short} {statistics.median(measured[c][key]):.2f}"
                             for short, key in PARTS[floor_of] if key in measured[c])
            frags = str(int(st["deep_gbuffer_fragments"])) if "deep_gbuffer_fragments" in st else ""
            # The attribute pass bins every sample on the CPU device once a deeper layer holds one, and a
            # textured material's samples everywhere (passes/gbuffer_attributes.cpp).
            binned = has_textures or (device == "cpu" and used > 1)
            extra = extra_bytes(method, st, args.width, args.height, layers, binned)
            table.append([how, layers, used, records.cell(ts), f"{med[c] / base:.2f}", f"{floor_ms:.2f}",
                          f"{x_floor:.2f}", frags, f"{extra / 2**20:.1f}", records.cell(cpu[c], 1),
                          f"{statistics.median(cpu[c]) / cpu_base:.2f}", parts])
        print(records.markdown(["method", "layers", "used", "ms", "x 1 peel", "floor ms", "x floor", "fragments",
                                "extra MiB", "cpu ms", "cpu x 1 peel", "parts (ms)"], table))
        # The shading floor: what any exact construction must do at least is shade and store every
        # fragment its layers keep once. Measured per fragment as layer 0's shading pass does it
        # (depth_peel.shade of the 1-layer peeled frame over layer 0's samples), that work alone
        # is this share of one layer.
        if ("peel", 8) in samples and samples.get(("peel", 1)):
            kept = sum(samples[("peel", 8)])
            first = samples[("peel", 1)][0]
            shade = statistics.median(measured[("peel", 1)].get("depth_peel.shade", [float("nan")]))
            shading_floors.append((name, kept / first, shade / base, shade * kept / first / base,
                                   scene.triangle_count / first))
        print()

    print("distance from the floor on this device: the construction's time over its floor (x floor, median of the "
          "rounds), and the floor in ms")
    for layers in sorted({l for (_, _, l) in distance} & {1, 8}):
        print(f"  {layers} layer{'s' if layers > 1 else ''}")
        rows = []
        for name in names:
            cells = []
            for m in args.methods:
                x, ms = distance.get((name, m, layers), (float("nan"), float("nan")))
                cells.append(f"{x:.2f}x of {ms:.2f} ms")
            rows.append([name, *cells])
        print(records.markdown(["scene", *args.methods], rows))

    here = (device, (args.width, args.height))
    print(f"\ngoals (set for llvmpipe at {GOAL_SIZE[0]}x{GOAL_SIZE[1]}"
          + ("" if here == (GOAL_DEVICE, GOAL_SIZE) else f"; this run: {device} at {args.width}x{args.height}, "
             "so the verdicts below are this run's, not the goals'") + "): the construction's time over its floor "
          "in each round, median [25th-75th percentile] of the rounds; met / not met where the middle half is on "
          "one side; beside it, not judged, the same rounds against one peeled layer")
    for name in names:
        if name not in GOAL_SCENES:
            continue
        print(f"  {name}: 8 layers <= {EIGHT_LAYER_GOAL:g}x the construction's floor")
        for m in args.methods:
            if (name, m, 8) in x_floor_rounds:
                r = x_floor_rounds[(name, m, 8)]
                print(f"    {m:<17} {quartiles(r):>22}: {verdict(r, EIGHT_LAYER_GOAL)}"
                      f"   (x one peeled layer {quartiles(summary[(name, m, 8)])})")
    for name in names:
        rows = [m for m in args.methods if m.startswith("visibility") and (name, m, 1) in x_floor_rounds]
        if rows and name in GOAL_SCENES:
            print(f"  {name}: 1 layer by visibility <= {ONE_LAYER_GOAL:g}x its floor")
            for m in rows:
                r = x_floor_rounds[(name, m, 1)]
                beside = [t / b for t, b in zip(summary[(name, m, 1)], summary[(name, "peel", 1)])]
                print(f"    {built_as[(name, m, 1)]:<17} {quartiles(r):>22}: {verdict(r, ONE_LAYER_GOAL)}"
                      f"   (x peeling's layer {quartiles(beside)})")

    if shading_floors:
        print("\nthe shading floor of an exact construction: 8 layers keep `kept` times layer 0's fragments, and each is")
        print("shaded and stored once at least; at layer 0's cost per fragment (its shading pass, `shade` of one peeled")
        print("layer's time) that alone is `floor` x one peeled layer, before any geometry, selection or sorting")
        print("(a bound only where the shading pass's time is its fragments': with more than one triangle per")
        print("hundred of layer 0's fragments, its vertex work counts too and the estimate is no bound)")
        rows = []
        for name, kept, share, floor, tri_per_fragment in shading_floors:
            why = ("geometry-bound: no bound" if tri_per_fragment > 0.01 else
                   f"no exact construction of 8 layers comes under {floor:.2f}x one peeled layer here")
            rows.append([name, f"{kept:.2f}", f"{share:.2f}", f"{floor:.2f}", f"{tri_per_fragment:.3f}", why])
        print(records.markdown(["scene", "kept", "shade", "floor", "tri/frag", "verdict"], rows))


if __name__ == "__main__":
    main()
