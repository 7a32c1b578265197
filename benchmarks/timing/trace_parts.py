"""What a ray of the Hi-Z trace pays besides its walk: the pass built up part by part.

    python benchmarks/timing/trace_parts.py [--repeats 11] [--set max_steps=1] [--scenes ...] [--device ...]

Writes copies of the installed shader tree into a temporary folder, each with a trace_hiz.comp whose
main() stops after one more part of the per-ray work (every copy still stores something, so that
no part is compiled away), and renders the 1-layer Hi-Z mirror frame with each copy, frames
interleaved round by round in one process after the protocol's warm-up rounds (timings never
include compilation). Recorded, and printed in a table rendered from the records: the trace
pass's GPU ms per copy, cumulative:
    entries         the list entries (or pixels) and one RGBA32F store per invocation
    + ray           the G-buffer fetches and the reflected ray (slot_ray)
    + set-up        the walk's set-up (projection, screen exit, first crossing)
    + walk          the walk and its loop (at max_steps=1: one step)
    + hit           the hit's cell bounds, position and fades
    full pass       the installed trace_hiz.comp (three RGBA32F stores per ray)
    full, 1 store   the full pass storing rays.hit only (rays.sample and rays.direction dropped)
The default --set max_steps=1 keeps every ray's work but the walk's length; `--set` with nothing
after it measures the full walk. The copies are instruments, not renderers: their images are wrong.
"""

from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.tools.ab_pass import HIZ_MIRROR  # noqa: E402
from ssrlab.lab import records  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402

SETUP = """void main() {
    g_max_level = min(ssr.hiz_max_level, hiz_levels() - 1);
    g_start_level = clamp(ssr.hiz_start_level, 0, g_max_level);
    g_stop_level = clamp(ssr.hiz_stop_level, 0, g_max_level);
    ivec3 id0, id1;
    bool has0 = slot_entry(0, id0), has1 = slot_entry(1, id1);
"""
RAYS = """    GSample g0, g1;
    bool keep0, keep1;
    ReflectionRay ray0 = slot_ray(id0, has0, g0, keep0);
    ReflectionRay ray1 = slot_ray(id1, has1, g1, keep1);
"""
WALKS = """    HizWalk w0 = walk_start(ray0, keep0 && ray0.weight > 0.0);
    HizWalk w1 = walk_start(ray1, keep1 && ray1.weight > 0.0);
"""
LOOP = """    while (w0.walking || w1.walking) {
        walk_step(w0);
        walk_step(w1);
    }
"""
HIT = """    HizHit h0 = walk_result(w0), h1 = walk_result(w1);
    vec4 a = vec4(0.0);
    if (h0.hit) a += vec4(h0.pixel, float(h0.layer), hit_fade(h0.pixel, ray0.origin, ray0.dir,
                          view_position(h0.pixel, view_depth_of_screen(h0.s))));
    if (h1.hit) a += vec4(h1.pixel, float(h1.layer), hit_fade(h1.pixel, ray1.origin, ray1.dir,
                          view_position(h1.pixel, view_depth_of_screen(h1.s))));
"""

# label: main() body after SETUP (None: the installed shader)
PARTS = {
    "entries": "    imageStore(o_hit, id0, vec4(id0.xy, id1.x, float(has0) + float(has1)));\n}\n",
    "+ ray": RAYS + "    imageStore(o_hit, id0, vec4(ray0.dir + ray1.dir + ray0.origin + ray1.origin,"
                    " ray0.weight + ray1.weight + float(keep0) + float(keep1)));\n}\n",
    "+ set-up": RAYS + WALKS + "    imageStore(o_hit, id0, vec4(w0.o + w1.o + w0.v + w1.v, w0.t + w1.t + w0.eps_t"
                               " + float(w0.walking) + float(w1.walking) + float(w0.level)));\n}\n",
    "+ walk": RAYS + WALKS + LOOP + "    imageStore(o_hit, id0, vec4(w0.t + w1.t, float(w0.layer + w1.layer),"
                                    " w0.front + w1.front, float(w0.level + w1.level)));\n}\n",
    "+ hit": RAYS + WALKS + LOOP + HIT + "    imageStore(o_hit, id0, a);\n}\n",
    "full pass": None,
    "full, 1 store": "store",
}


def make_copy(src: Path, dst: Path, body) -> None:
    shutil.copytree(src, dst)
    if body is None:
        return
    if body == "store":
        common = dst / "lib" / "trace_common.glsl"
        text = common.read_text()
        kept = [line for line in text.splitlines(keepends=True)
                if not line.lstrip().startswith(("imageStore(o_sample", "imageStore(o_direction"))]
        if len(kept) != len(text.splitlines()) - 2:
            raise RuntimeError(f"{common}: store_ray's stores are not where this benchmark expects them")
        common.write_text("".join(kept))
        return
    trace = dst / "passes" / "trace_hiz.comp"
    text = trace.read_text()
    if "void main() {" not in text:
        raise RuntimeError(f"{trace}: no main() to replace")
    trace.write_text(text[:text.index("void main() {")] + SETUP + body)


def main(argv=None) -> int:
    ap = benchmark_arguments(__doc__, repeats=11)
    ap.add_argument("--set", nargs="*", default=["max_steps=1"], metavar="KEY=VALUE", help="settings overrides")
    args = ap.parse_args(argv)
    import ssrlab

    first = open_renderer(args)
    try:
        bench = Bench("trace_parts", args, first)  # parses --set (ssrlab.lab.protocol.parse_set)
    except ValueError as e:
        ap.error(str(e))
    kw = {**HIZ_MIRROR, **bench.settings}
    with tempfile.TemporaryDirectory() as tmp:
        renderers = {}
        for i, (label, body) in enumerate(PARTS.items()):
            folder = Path(tmp) / f"part{i}"
            make_copy(ssrlab.shader_dir(), folder, body)
            renderers[label] = ssrlab.Renderer(args.device, shader_dir=str(folder))
        print(f"{args.width}x{args.height}, {', '.join(f'{k}={v}' for k, v in kw.items())}; trace_hiz GPU ms of "
              f"{args.repeats} rounds after {bench.warmup} warm-up rounds, frames interleaved")
        for scene_name in args.scenes:
            scene = getattr(ssrlab.scenes, scene_name)()
            s = ssrlab.Settings(width=args.width, height=args.height, **kw)
            ms = bench.rounds({label: (lambda r=r: {"trace_hiz": r.render(scene, settings=s).timings["trace_hiz"]})
                               for label, r in renderers.items()})
            for label in PARTS:
                bench.record(dict(scene=scene_name, part=label, width=args.width, height=args.height,
                                  settings=bench.settings), "trace_hiz", "ms", ms[label]["trace_hiz"])
    rows = []
    for scene_name in args.scenes:
        cells = []
        for label in PARTS:
            s = records.summary(bench.find("trace_hiz", scene=scene_name, part=label)[0]["samples"])
            cells.append(f"{s['median']:.2f} ({s['min']:.2f}-{s['max']:.2f})")
        rows.append([scene_name, *cells])
    print("trace_hiz GPU ms, median (min-max) of the rounds")
    print(records.markdown(["scene", *PARTS], rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
