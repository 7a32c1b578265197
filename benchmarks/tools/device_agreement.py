"""Do two devices render the same images? Frames saved on one machine, compared on another.

    python benchmarks/tools/device_agreement.py save frames_gpu.npz [--device gpu] [--width 320 --height 180]
    python benchmarks/tools/device_agreement.py compare frames_gpu.npz frames_cpu.npz

`save` renders every scene at three configurations (the thesis's, one layer of Hi-Z mirror rays,
and 4 layers with 4 rays at the defaults) and writes each frame's colour and reflection. `compare`
prints, per image, the thesis error between the two files, the mean and largest absolute
difference, and the share of pixels differing by more than 0.05 in some channel. The devices'
arithmetic differs (hardware shadow-map filtering, fused multiply-adds, transcendental
functions), so the images agree closely, not bit for bit; same device and seed: identical.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import device_header  # noqa: E402

CONFIGS = {
    "thesis": dict(layers=4, rays_per_pixel=4, stride=4.0, downscale=2, max_steps=250),
    "hiz_mirror": dict(layers=1, method="hiz", sampling="mirror"),
    "default4": dict(layers=4, rays_per_pixel=4),
}


def save(args) -> int:
    import ssrlab

    r = ssrlab.Renderer(args.device)
    print(device_header(r))
    arrays = {}
    for scene in args.scenes:
        for name, kw in CONFIGS.items():
            f = r.render(ssrlab.scenes.load(scene), settings=ssrlab.Settings(width=args.width, height=args.height, **kw))
            arrays[f"{scene}.{name}.color"] = f.color
            arrays[f"{scene}.{name}.reflection"] = f.reflection
    np.savez_compressed(args.out, renderer=np.array(r.info["renderer"]), **arrays)
    print(f"wrote {len(arrays)} images to {args.out}")
    return 0


def compare(args) -> int:
    from ssrlab.metrics import thesis_error

    a, b = np.load(args.a), np.load(args.b)
    name = lambda f, path: str(f["renderer"]) if "renderer" in f.files else path  # noqa: E731
    print(f"{name(a, args.a)}  vs  {name(b, args.b)}")
    print("| image | thesis error | mean abs diff | largest abs diff | pixels > 0.05 |\n|---|---|---|---|---|")
    for k in sorted(set(a.files) & set(b.files) - {"renderer"}):
        x, y = a[k], b[k]
        if x.shape != y.shape:
            print(f"| {k} | shapes differ: {x.shape} vs {y.shape} | | | |")
            continue
        d = np.abs(x.astype(np.float64) - y)
        print(f"| {k} | {thesis_error(x, y):.5f} | {d.mean():.5f} | {d.max():.3f} | "
              f"{100 * (d.max(axis=-1) > 0.05).mean():.2f} % |")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="command", required=True)
    s = sub.add_parser("save", help="render the frames on this machine's device and save them")
    s.add_argument("out")
    s.add_argument("--device", default="auto", choices=("auto", "gpu", "cpu"))
    s.add_argument("--width", type=int, default=320)
    s.add_argument("--height", type=int, default=180)
    s.add_argument("--scenes", nargs="+", default=["spheres_and_boxes", "hall"])
    s.set_defaults(func=save)
    c = sub.add_parser("compare", help="compare two saved files image by image")
    c.add_argument("a")
    c.add_argument("b")
    c.set_defaults(func=compare)
    args = ap.parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
