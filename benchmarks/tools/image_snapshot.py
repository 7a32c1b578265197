"""Images of a fixed set of scenes, saved from one build and compared with another's, array by array:
the check that a change meant to keep every value (a refactoring, a cheaper shader variant) does.

    python benchmarks/tools/image_snapshot.py save before.npz      # with the build before the change
    python benchmarks/tools/image_snapshot.py save after.npz       # with the build after it
    python benchmarks/tools/image_snapshot.py compare before.npz after.npz

The scenes: spheres_and_boxes, Suzanne and 2CylinderEngine on a mirror stage (skipped, and said so,
where the sample models are missing), and ssrlab.crosscheck's emissive-texture and masked scenes;
each rendered at 160x96 with 2 layers by peeling and by the one-pass lists. Saved per render:
frame.color, gbuffer.normal and gbuffer.albedo. `compare` prints every array that differs, with
its largest difference, and the count of equal ones.
"""

from __future__ import annotations

import sys
from pathlib import Path
import argparse

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import open_renderer  # noqa: E402

import ssrlab  # noqa: E402
from ssrlab import crosscheck as cc  # noqa: E402


def scenes() -> dict:
    out = {"spheres_and_boxes": ssrlab.scenes.load("spheres_and_boxes")}
    for name in ("Suzanne", "2CylinderEngine"):
        try:
            out[name] = ssrlab.scenes.load(str(ssrlab.models.find(name)), stage="mirror")
        except Exception as e:  # a missing sample model skips its scene, and says why
            print(f"{name}: skipped ({e})")
    out["emissive_texture"] = cc.emissive_texture_crosscheck_scene()
    out["masked"] = cc.masked_crosscheck_scene()
    return out


def save(path: str, device: str) -> None:
    renderer = open_renderer(argparse.Namespace(device=device))
    arrays = {}
    for name, scene in scenes().items():
        for method in ("peel", "lists"):
            f = renderer.render(scene, settings=ssrlab.Settings(width=160, height=96, layers=2, deep_gbuffer=method))
            arrays[f"{name}/{method}/color"] = f.color
            arrays[f"{name}/{method}/normal"] = f.gbuffer.normal
            arrays[f"{name}/{method}/albedo"] = f.gbuffer.albedo
    np.savez(path, **arrays)
    print(f"saved {len(arrays)} arrays to {path}")


def compare(a_path: str, b_path: str) -> None:
    a, b = np.load(a_path), np.load(b_path)
    missing = sorted(set(a.files) ^ set(b.files))
    if missing:
        print(f"in one file only: {', '.join(missing)}")
    equal = 0
    for key in sorted(set(a.files) & set(b.files)):
        if a[key].shape == b[key].shape and np.array_equal(a[key], b[key]):
            equal += 1
        elif a[key].shape != b[key].shape:
            print(f"{key}: shapes {a[key].shape} and {b[key].shape}")
        else:
            print(f"{key}: differs, largest difference {np.abs(a[key] - b[key]).max():.3e}")
    print(f"{equal} of {len(set(a.files) & set(b.files))} arrays equal bit for bit")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mode", choices=("save", "compare"))
    ap.add_argument("files", nargs="+")
    ap.add_argument("--device", default="auto", choices=("auto", "gpu", "cpu"))
    args = ap.parse_args()
    if args.mode == "save":
        save(args.files[0], args.device)
    else:
        if len(args.files) != 2:
            ap.error("compare takes two files")
        compare(*args.files)


if __name__ == "__main__":
    main()
