"""Where the deep G-buffer's peeling and the lighting pass spend their GPU time, part by part.

    python benchmarks/peel_profile.py [--width 1920 --height 1080] [--device gpu] [--repeats 15]

Per scene and layer count: the median GPU ms (with min-max) of the peeling's parts, summed over
the layers (`depth_peel.setup`: clears and the copy of the previous layer's depth; `.depth`: the
depth-only peel; `.shade`: the material pass at GL_EQUAL) and of the lighting pass's parts
(`lighting.list`, `.clear`, `.shade`), under two protocols:
  back-to-back  renders issued one after the other (the device stays busy: clocks up)
  paced         a 50 ms pause before each render (what a script that renders, reads back and
                works on each frame does: a GPU may lower its clocks in the pauses)
Then timing-only experiments on copies of the shaders (`Renderer(shader_dir=...)`), whose images
are not meant to be right: `no_tile_flags` drops the peeling shader's covered-tile and
reflective-region stores (storage-buffer writes from every fragment). The ratio of each
experiment to the base says what that part of the shader costs on the device.
"""

from __future__ import annotations

import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import benchmark_arguments, device_header  # noqa: E402

PARTS = ["depth_peel", "depth_peel.setup", "depth_peel.depth", "depth_peel.shade", "lighting", "lighting.list",
         "lighting.clear", "lighting.shade", "total"]


def shader_variant(root: Path, name: str) -> Path:
    """A copy of the shader folder with one timing-only change."""
    import ssrlab

    src = Path(ssrlab.shader_dir())
    dst = root / name
    shutil.copytree(src, dst)
    if name == "no_tile_flags":
        frag = dst / "passes" / "depth_peel.frag"
        text = frag.read_text()
        store = "covered_tile[(u_layer * grid.y + tile.y) * grid.x + tile.x] = 1u;"
        region = "if (u_layer == 0 && g.reflectivity > 0.0) {"
        if store not in text or region not in text:
            raise SystemExit(f"peel_profile: {frag} no longer has the stores this experiment removes")
        frag.write_text(text.replace(store, "").replace(region, "if (false) {"))
    return dst


def measure(renderer, scene, settings, repeats: int, pause: float) -> dict[str, list[float]]:
    for _ in range(3):
        renderer.render(scene, settings=settings).timings
    runs = []
    for _ in range(repeats):
        if pause:
            time.sleep(pause)
        runs.append(renderer.render(scene, settings=settings).timings)
    return {k: [r.get(k, float("nan")) for r in runs] for k in PARTS}


def row(label: str, samples: dict[str, list[float]]) -> str:
    cells = []
    for k in PARTS:
        v = samples[k]
        cells.append(f"{statistics.median(v):7.3f} ({min(v):.3f}-{max(v):.3f})")
    return f"{label:<34}" + " ".join(cells)


def main(argv=None) -> int:
    ap = benchmark_arguments(__doc__, repeats=15)
    ap.set_defaults(width=1920, height=1080, scenes=["hall", "spheres_and_boxes"])
    ap.add_argument("--layers", type=int, nargs="+", default=[1, 4])
    ap.add_argument("--no-experiments", action="store_true")
    args = ap.parse_args(argv)
    import ssrlab

    base = ssrlab.Renderer(args.device)
    print(device_header(base))
    print(f"{args.width}x{args.height}; GPU ms, median (min-max) of {args.repeats} renders after 3 warm-up renders")
    print(f"{'case':<34}" + " ".join(f"{k:>21}" for k in PARTS))
    with tempfile.TemporaryDirectory() as tmp:
        renderers = {"base": base}
        if not args.no_experiments:
            renderers["no_tile_flags"] = ssrlab.Renderer(args.device, shader_dir=str(shader_variant(Path(tmp),
                                                                                                 "no_tile_flags")))
        for scene_name in args.scenes:
            scene = ssrlab.scenes.load(scene_name)
            for layers in args.layers:
                s = ssrlab.Settings(width=args.width, height=args.height, layers=layers, method="hiz",
                                    sampling="mirror", rays_per_pixel=1, reuse_radius=1)
                for rname, r in renderers.items():
                    protocols = [("back-to-back", 0.0)] + ([("paced", 0.05)] if rname == "base" else [])
                    for pname, pause in protocols:
                        print(row(f"{scene_name} L{layers} {rname} {pname}", measure(r, scene, s, args.repeats,
                                                                                       pause)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
