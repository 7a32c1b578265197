"""The ssrlab command line.

    ssrlab info                         the device and OpenGL implementation chosen
    ssrlab scenes                       the procedural scenes
    ssrlab render [--scene NAME|FILE]   render a scene, write its image, G-buffer and timings
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


def cmd_render(args) -> int:
    from tqdm import tqdm

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
    r.set_defaults(func=cmd_render)

    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, FileNotFoundError, RuntimeError) as e:
        print(f"ssrlab: {type(e).__name__}: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
