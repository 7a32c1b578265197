"""A minimum separation between the deep G-buffer's layers (Mara, McGuire, Nowrouzezahrai and
Luebke 2016) against plain two-layer depth peeling: what it does to the reflections' error.

    python benchmarks/studies/min_separation.py [--width 320 --height 180 --frames 6 --reference-rays 64
                                         --separations 0.05 0.2 0.5 --scenes occluder hall]

Settings.min_separation makes layer 1 the nearest surface at least that far (view depth, world
units) behind layer 0, instead of the nearest one strictly behind it (often the back of the
very surface layer 0 holds). For the thesis's occluder scene (spheres_and_boxes with Suzanne,
seed 000 3.2.1) and hall, with a static camera (the scene's own, `frames` frames: render_sequence
of one camera, each frame drawing new rays, seed + i) and a moving camera (render_sequence along
a sideways slide of `frames` frames; hall: its documented path), renders SSR at the thesis's
settings (seed 000, 3.2: 4 rays, stride 4, half resolution, 250 steps; no TAA, no temporal
accumulation) with 1 layer, 2 plain layers (separation 0) and 2 layers at each separation, and
scores every frame against the converged reference of its own camera (ssrlab.reference,
`reference-rays` rays a pixel, cached on disk). The layers are built by the fragment lists,
whose layers equal peeling's bit for bit at every separation (tests/test_deep_gbuffer.py).

Printed per scene and camera: the mean over the frames of the thesis's error over the
reflective pixels (thesis_error_reflective) and of rmse_reflective; for each separation the
mean paired difference to 2 plain layers (same frames, same rays) with its standard error over
the frames, the share of pixels whose layer 1 changed, and the verdict computed from them:
"lower" or "higher" where the difference exceeds twice its standard error, else "no difference
beyond the frames' noise". Every error is a record with one sample per frame (the share of
changed pixels one per frame too); the tables are rendered from the records.
"""

from __future__ import annotations

import sys
from pathlib import Path
import math
import statistics

import numpy as np

import ssrlab

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab import records  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402
from ssrlab.experiments import THESIS_SETTINGS  # noqa: E402
from ssrlab.metrics import image_metrics  # noqa: E402
from ssrlab.reference import reference_image  # noqa: E402
from ssrlab.sequence import hall_path  # noqa: E402

SCENES = {
    "occluder": ("spheres_and_boxes(with_suzanne=True)", lambda: ssrlab.scenes.load("spheres_and_boxes",
                                                                                    with_suzanne=True)),
    "hall": ("hall", lambda: ssrlab.scenes.load("hall")),
}
ERROR = "thesis_error_reflective"


def slide(camera, frames: int) -> list:
    """A sideways slide of the camera around its target: 15 % of the distance to it either way."""
    pos, target = np.array(camera.position, float), np.array(camera.target, float)
    forward = target - pos
    right = np.cross(forward, np.array(camera.up, float))
    right *= 0.15 * np.linalg.norm(forward) / np.linalg.norm(right)
    path = ssrlab.CameraPath([pos - right, pos + right], [target], frames, up=tuple(camera.up),
                             fov_y=camera.fov_y, near=camera.near, far=camera.far)
    return list(path)


def verdict(diffs: list[float]) -> tuple[float, float, str]:
    """Mean paired difference, its standard error, and what they say (see the module notes)."""
    mean = statistics.fmean(diffs)
    se = statistics.stdev(diffs) / math.sqrt(len(diffs)) if len(diffs) > 1 else float("inf")
    if not math.isfinite(se):
        return mean, se, "too few frames to judge"
    if abs(mean) <= 2 * se or mean == 0:
        return mean, se, "no difference beyond the frames' noise"
    return mean, se, "lower" if mean < 0 else "higher"


def main() -> None:
    ap = benchmark_arguments(__doc__)
    ap.set_defaults(width=320, height=180, scenes=list(SCENES))
    ap.add_argument("--frames", type=int, default=6)
    ap.add_argument("--reference-rays", type=int, default=64)
    ap.add_argument("--separations", type=float, nargs="+", default=[0.05, 0.2, 0.5])
    args = ap.parse_args()
    if args.frames < 2:
        ap.error("--frames must be at least 2 (the noise is measured over the frames)")
    unknown = [s for s in args.scenes if s not in SCENES]
    if unknown:
        ap.error(f"--scenes: unknown {unknown}; choose from {list(SCENES)}")
    renderer = open_renderer(args)
    bench = Bench("min_separation", args, renderer)
    base = ssrlab.Settings(width=args.width, height=args.height, deep_gbuffer="lists", **THESIS_SETTINGS)
    configs = {"1 layer": base.replace(layers=1), "2 layers": base.replace(layers=2)}
    for sep in args.separations:
        configs[f"2 layers, {sep:g} m"] = base.replace(layers=2, min_separation=sep)
    print(f"{args.width}x{args.height}, thesis settings {THESIS_SETTINGS}, {args.frames} frames per camera, "
          f"converged references of {args.reference_rays} rays a pixel; error: {ERROR} (and rmse_reflective), "
          f"mean over the frames\n")
    verdicts = []
    for key in args.scenes:
        label, make = SCENES[key]
        scene = make()
        cams = {"static": [scene.camera] * args.frames,
                "moving": hall_path(args.frames) if key == "hall" else slide(scene.camera, args.frames)}
        for how, cameras in cams.items():
            cameras = list(cameras)
            refs = [reference_image(renderer, scene, c, base, kind="converged", rays=args.reference_rays)
                    for c in cameras]
            errors, rmses, layer1 = {}, {}, {}
            plain_depth = {}  # frame -> layer 1's depth with 2 plain layers
            for name, s in configs.items():
                errors[name], rmses[name], changed = [], [], []
                for i, f in enumerate(renderer.render_sequence(scene, cameras, s)):
                    m = image_metrics(f.color, refs[i].color, refs[i].reflective, perceptual=False)
                    errors[name].append(m[ERROR])
                    rmses[name].append(m["rmse_reflective"])
                    if name == "2 layers":
                        plain_depth[i] = f.gbuffer.window_depth[1].copy()
                    elif s.layers == 2:
                        changed.append(float(np.mean(f.gbuffer.window_depth[1] != plain_depth[i])))
                    f.release()
                params = dict(scene=key, camera=how, configuration=name, frames=len(cameras), width=args.width,
                              height=args.height, reference_rays=args.reference_rays)
                bench.record(params, ERROR, "", errors[name])
                bench.record(params, "rmse_reflective", "", rmses[name])
                if changed:
                    bench.record(params, "layer1_changed", "share", changed)
                layer1[name] = statistics.fmean(changed) if changed else None
            print(f"{label}, {how} camera ({len(cameras)} frames, {int(refs[0].reflective.sum())} reflective "
                  f"pixels in frame 0)")
            rows = []
            for name in configs:
                e, r = statistics.fmean(errors[name]), statistics.fmean(rmses[name])
                ch = f"{100 * layer1[name]:.1f} %" if layer1[name] is not None else ""
                if name == "2 layers":
                    rows.append([name, f"{e:.5f}", f"{r:.5f}", ch, "(baseline)", ""])
                    continue
                diffs = [a - b for a, b in zip(errors[name], errors["2 layers"])]
                mean, se, word = verdict(diffs)
                rows.append([name, f"{e:.5f}", f"{r:.5f}", ch, f"{mean:+.5f} ± {se:.5f}", word])
                if name != "1 layer":
                    verdicts.append((label, how, name, word))
            print(records.markdown(["configuration", f"{ERROR} (mean)", "rmse_reflective (mean)", "layer 1 changed",
                                    "vs 2 layers (± s.e.)", "verdict"], rows))
            print()
    print("verdict: 2 layers with a minimum separation against 2 plain peeled layers, error against the converged "
          "reference")
    print(records.markdown(["scene", "camera", "configuration", "verdict"], [list(v) for v in verdicts]))


if __name__ == "__main__":
    main()
