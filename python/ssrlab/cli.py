"""The ssrlab command line.

    ssrlab info                         the device and OpenGL implementation chosen
    ssrlab scenes                       the procedural scenes
    ssrlab render [--scene NAME|FILE]   render a scene, write its image, G-buffer and timings
    ssrlab bench SWEEP_FILE             sweep settings, measure run time against error (ssrlab.bench)
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


def _parse_value(text: str):
    try:
        return json.loads(text)
    except ValueError:
        return text


def _settings_from_args(args) -> "Settings":
    from .settings import Settings

    changes = {}
    for item in args.set or []:
        if "=" not in item:
            raise SystemExit(f"ssrlab: --set expects FIELD=VALUE, got {item!r}")
        key, value = item.split("=", 1)
        changes[key.strip()] = _parse_value(value.strip())
    for name in ("width", "height", "layers"):
        if getattr(args, name) is not None:
            changes[name] = getattr(args, name)
    try:
        return Settings().replace(**changes)
    except ValueError as e:
        raise SystemExit(f"ssrlab: {e}") from None


def cmd_info(args) -> int:
    from .renderer import Renderer

    info = Renderer(args.device).info
    width = max(len(k) for k in info)
    for k, v in info.items():
        if v:
            print(f"{k:<{width}}  {v}")
    return 0


def cmd_scenes(args) -> int:
    from . import scenes

    for name, builder in scenes.SCENES.items():
        print(f"{name:<20} {(builder.__doc__ or '').strip().splitlines()[0]}")
    return 0


def _camera_path(args, scene):
    from .sequence import CameraPath

    if args.frames < 1:
        raise SystemExit(f"ssrlab: --frames must be >= 1, got {args.frames}")
    cam = scene.camera
    positions = [tuple(cam.position)]
    if args.path:
        try:
            positions = [tuple(float(v) for v in key.split(",")) for key in args.path.split(";") if key.strip()]
        except ValueError:
            raise SystemExit(f"ssrlab: --path expects X,Y,Z;X,Y,Z;..., got {args.path!r}") from None
    try:
        return CameraPath(positions, [tuple(cam.target)], args.frames, up=tuple(cam.up), fov_y=cam.fov_y,
                          near=cam.near, far=cam.far)
    except ValueError as e:
        raise SystemExit(f"ssrlab: --path: {e}") from None


def cmd_render_sequence(args) -> int:
    import json as _json

    from . import scenes
    from .io import OutputFolder, linear_to_srgb, write_image
    from .renderer import Renderer

    settings = _settings_from_args(args)
    out = Path(args.out) if args.out else Path("renders") / (Path(args.scene).stem + "_sequence")
    renderer = Renderer(args.device)
    kwargs = {"seed": args.seed} if args.seed is not None else {}
    scene = scenes.load(args.scene, **kwargs)
    path = _camera_path(args, scene)
    names = [f"frame_{i:04d}.png" for i in range(len(path))] + ["frames.gif", "timings.json"]
    folder = OutputFolder(out, overwrite=args.overwrite)
    try:
        folder.check(names)
    except FileExistsError as e:
        print(f"ssrlab: {e}", file=sys.stderr)
        return 1
    images, timings = [], []
    for i, frame in enumerate(renderer.render_sequence(scene, path, settings)):
        srgb = linear_to_srgb(frame.color, args.exposure)
        folder.write(names[i], lambda p, a=srgb: write_image(p, a))
        images.append(srgb)
        timings.append(frame.timings)
        print(f"frame {i}: {frame.timings['total']:.3f} ms (GPU)")
    try:  # Pillow comes with matplotlib; without it the numbered images stand alone
        from PIL import Image

        import numpy as np

        def gif(p):
            pics = [Image.fromarray(np.clip(np.rint(a * 255), 0, 255).astype(np.uint8)) for a in images]
            pics[0].save(p, format="GIF", save_all=True, append_images=pics[1:], duration=40, loop=0)

        folder.write("frames.gif", gif)
    except ImportError:
        pass
    folder.write("timings.json", lambda p: p.write_text(_json.dumps(
        {"scene": scene.name, "device": renderer.info, "settings": settings.to_dict(), "frames": timings}, indent=1)))
    print(f"wrote {len(images)} frames to {out}")
    return 0


def cmd_render(args) -> int:
    from tqdm import tqdm

    if args.frames != 1 or args.path:
        return cmd_render_sequence(args)

    from . import scenes
    from .renderer import Renderer

    settings = _settings_from_args(args)
    out = Path(args.out) if args.out else Path("renders") / Path(args.scene).stem
    with tqdm(total=5, desc="ssrlab render", unit="step", file=sys.stderr,
              bar_format="{desc}: {n}/{total} {postfix}") as bar:
        bar.set_postfix_str("opening the GL device")
        renderer = Renderer(args.device)
        bar.update(1)
        bar.set_postfix_str(f"building scene {args.scene}")
        kwargs = {"seed": args.seed} if args.seed is not None else {}
        scene = scenes.load(args.scene, **kwargs)
        bar.update(1)
        bar.set_postfix_str(f"rendering {settings.width}x{settings.height}, {settings.layers} layer(s)")
        frame = renderer.render(scene, settings=settings)
        bar.update(1)
        bar.set_postfix_str(f"writing {out}")
        try:
            files = frame.save(out, overwrite=args.overwrite, exposure=args.exposure, extra={
                "scene": scene.name, "scene_source": args.scene, "triangles": scene.triangle_count,
                "device": renderer.info})
        except FileExistsError as e:
            bar.close()
            print(f"ssrlab: {e}", file=sys.stderr)
            return 1
        bar.update(2)
        bar.set_postfix_str("done")
    print(f"{renderer.info['renderer']} ({renderer.info['device']}): {scene}")
    for name, ms in sorted(frame.timings.items()):
        print(f"  {name:<24} {ms:9.3f} ms (GPU)")
    for f in files:
        print(f"wrote {f}")
    return 0


def _format_cell(value) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    return "-" if value is None else str(value)


def _table(rows: list[dict], columns: list[str]) -> str:
    """A plain text table of some columns of rows."""
    cells = [columns] + [[_format_cell(r.get(c)) for c in columns] for r in rows]
    widths = [max(len(line[i]) for line in cells) for i in range(len(columns))]
    return "\n".join("  ".join(c.rjust(w) for c, w in zip(line, widths)) for line in cells)


def cmd_bench(args) -> int:
    from . import bench

    try:
        config = bench.load_sweep(args.sweep_file)
    except (ValueError, FileNotFoundError) as e:
        print(f"ssrlab: {e}", file=sys.stderr)
        return 1
    out = Path(args.out) if args.out else Path("results") / Path(args.sweep_file).stem
    if args.workers is not None and args.executor != "dask":
        raise SystemExit("ssrlab: --workers applies to --executor dask")
    if args.workers is not None and args.workers < 1:
        raise SystemExit(f"ssrlab: --workers must be >= 1, got {args.workers}")
    if args.device != "auto" or "device" not in config:  # --device given on the command line wins
        config["device"] = args.device
    if not (args.time_key in bench.TIME_KEYS or (args.time_key.startswith("gpu_") and args.time_key.endswith("_ms"))):
        raise SystemExit(f"ssrlab: --time-key must be one of {', '.join(bench.TIME_KEYS)} or a gpu_<pass>_ms "
                         f"column, got {args.time_key!r}")
    # Refuse before a long sweep, not after it, when the results could not be written.
    grid = config.get("grid") or {}
    varying = [k for k, v in grid.items() if isinstance(v, list) and len(set(map(repr, v))) > 1]
    try:
        from .io import OutputFolder

        OutputFolder(out, overwrite=args.overwrite).check(bench.result_names(varying))
    except (FileExistsError, NotADirectoryError) as e:
        print(f"ssrlab: {e}", file=sys.stderr)
        return 1

    cluster = client = None
    try:
        if args.executor == "dask":
            try:
                from distributed import Client, LocalCluster
            except ImportError:
                raise SystemExit("ssrlab: --executor dask needs dask.distributed: pip install 'ssrlab[dask]'")
            import os

            workers = args.workers or os.cpu_count() or 1
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
            client = Client(cluster)
            print(f"dask: {workers} worker process(es), one thread each", file=sys.stderr)
        rows = bench.sweep(**config, executor=client, progress=True)
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()

    try:
        files = bench.write_results(rows, out, time_key=args.time_key, error_key=args.error_key,
                                    overwrite=args.overwrite)
    except FileExistsError as e:
        print(f"ssrlab: {e}", file=sys.stderr)
        return 1
    front = bench.pareto_front(rows, args.time_key, args.error_key)
    first = rows[0]
    print(f"{len(rows)} configuration(s) on {first['gl_renderer']} ({first['device']}), reference "
          f"{first['reference']}, ssrlab {first['ssrlab_version']} ({first['git_revision']})")
    print(f"Pareto front ({args.error_key} against {args.time_key}):")
    columns = ["scene", "view", *[bench.SETTINGS_PREFIX + k for k in bench.varying_settings(rows)],
               args.time_key, args.error_key]
    print(_table(front, list(dict.fromkeys(columns))))
    for f in files:
        print(f"wrote {f}")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="ssrlab", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--device", default="auto", choices=("auto", "gpu", "cpu"),
                        help="EGL device: the GPU when there is one (auto), the GPU or fail (gpu), llvmpipe (cpu)")
    sub = parser.add_subparsers(dest="command", required=True)

    sub.add_parser("info", help="show the device and OpenGL implementation").set_defaults(func=cmd_info)
    sub.add_parser("scenes", help="list the procedural scenes").set_defaults(func=cmd_scenes)

    r = sub.add_parser("render", help="render a scene and write its image, G-buffer layers and timings")
    r.add_argument("--scene", default="spheres_and_boxes", help="a procedural scene name or a .gltf/.glb file")
    r.add_argument("--seed", type=int, help="seed of a procedural scene")
    r.add_argument("--width", type=int)
    r.add_argument("--height", type=int)
    r.add_argument("--layers", type=int)
    r.add_argument("--set", action="append", metavar="FIELD=VALUE",
                   help="any ssrlab.Settings field, e.g. --set depth_mode=reversed_z (repeatable)")
    r.add_argument("--out", help="output folder (default: renders/<scene>)")
    r.add_argument("--exposure", type=float, default=1.0, help="scale of linear radiance before sRGB encoding")
    r.add_argument("--overwrite", action="store_true",
                   help="replace existing files even if ssrlab did not write them")
    r.add_argument("--frames", type=int, default=1,
                   help="render a sequence of this many frames (Renderer.render_sequence), written as "
                        "frame_NNNN.png, frames.gif and timings.json")
    r.add_argument("--path", metavar="X,Y,Z;X,Y,Z;...",
                   help="camera position keyframes of the sequence (ssrlab.CameraPath), looking at the scene "
                        "camera's target; default: the scene camera, static")
    r.set_defaults(func=cmd_render)

    bench_error_keys = ("thesis_error", "rmse", "thesis_error_reflective", "rmse_reflective")
    b = sub.add_parser("bench", help="sweep settings from a sweep file; write run time against error",
                       description="Runs the sweep of SWEEP_FILE (TOML or JSON, see ssrlab.bench.load_sweep), "
                                   "then writes rows.csv, rows.json, pareto.csv and plots into --out and prints "
                                   "the Pareto front.")
    b.add_argument("sweep_file", metavar="SWEEP_FILE", help="a sweep file, e.g. benchmarks/sweeps/layers.toml")
    b.add_argument("--out", help="output folder (default: results/<sweep file name>)")
    b.add_argument("--executor", choices=("local", "dask"), default="local",
                   help="local: this process, one configuration after another; dask: a local dask.distributed "
                        "cluster of worker processes, each with its own EGL context")
    b.add_argument("--workers", type=int, help="dask worker processes (default: the CPU count)")
    b.add_argument("--overwrite", action="store_true",
                   help="replace existing files even if ssrlab did not write them")
    b.add_argument("--time-key", default="time_frame_ms",
                   help="row column of the time axis, e.g. time_reflections_ms (default: %(default)s)")
    b.add_argument("--error-key", default="thesis_error", choices=bench_error_keys,
                   help="row column of the error axis, lower is better (default: %(default)s)")
    b.set_defaults(func=cmd_bench)

    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, FileNotFoundError, RuntimeError) as e:
        print(f"ssrlab: {type(e).__name__}: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
