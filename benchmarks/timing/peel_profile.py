"""Where the deep G-buffer's peeling and the lighting pass spend their GPU time, part by part.

    python benchmarks/timing/peel_profile.py [--width 1920 --height 1080] [--device gpu] [--repeats 15]

Per scene and layer count: the median GPU ms (with min-max) of the peeling's parts, summed over
the layers (`depth_peel.setup`: clears and the copy of the previous layer's depth; `.depth`: the
depth-only peel; `.shade`: the material pass at GL_EQUAL) and of the lighting pass's parts
(`lighting.list`, `.clear`, `.shade`), for both clear paths (Renderer.clear_path "gl": glClearTexSubImage and framebuffer clears;
"compute": image stores), the two alternating render by render with renders issued back to back,
(with --fresh also with every frame kept alive, so that each render allocates new textures and
the costs of a texture's first use show), then the device's default path "paced": a 50 ms pause before each render (what a script that
renders, reads back and works on each frame does: a GPU may lower its clocks in the pauses).
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

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, device_header  # noqa: E402

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


def measure(renderer, scene, settings, repeats: int, pause: float, clear_paths=("auto",), keep: bool = False) -> dict:
    """Timings per clear path, the paths alternating render by render (an interleaved A/B).
    keep: every frame is kept alive until the end, so each render allocates new textures (what a
    script that keeps its frames does): costs of a texture's first use show."""
    kept = []
    for path in clear_paths:
        renderer.clear_path = path
        for _ in range(3):
            renderer.render(scene, settings=settings).timings
    runs = {path: [] for path in clear_paths}
    for _ in range(repeats):
        for path in clear_paths:
            renderer.clear_path = path
            if pause:
                time.sleep(pause)
            frame = renderer.render(scene, settings=settings)
            runs[path].append(frame.timings)
            if keep:
                kept.append(frame)
    renderer.clear_path = "auto"
    return {path: {k: [r.get(k, float("nan")) for r in rs] for k in PARTS} for path, rs in runs.items()}


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
    ap.add_argument("--fresh", action="store_true",
                    help="also with every frame kept alive (new textures each render: first-use costs show)")
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
                    if rname == "base":
                        # the clear paths A/B, back to back, then the default path paced
                        for path, samples in measure(r, scene, s, args.repeats, 0.0, ("gl", "compute")).items():
                            print(row(f"{scene_name} L{layers} clear={path}", samples), flush=True)
                        print(row(f"{scene_name} L{layers} paced", measure(r, scene, s, args.repeats, 0.05)["auto"]),
                              flush=True)
                        if args.fresh:
                            for path, samples in measure(r, scene, s, args.repeats, 0.0, ("gl", "compute"),
                                                         keep=True).items():
                                print(row(f"{scene_name} L{layers} kept clear={path}", samples), flush=True)
                    else:
                        print(row(f"{scene_name} L{layers} {rname}", measure(r, scene, s, args.repeats, 0.0)["auto"]),
                              flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
