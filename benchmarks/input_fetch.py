"""How the passes read their float inputs: Renderer(input_fetch="texelFetch") against "imageLoad",
A/B in one run.

    python benchmarks/input_fetch.py [--width 1920 --height 1080] [--device gpu] [--repeats 9]

Two renderers on the same device, one per input fetch (shaders/lib/input_fetch.glsl), render the
same scene and settings alternately, frame by frame, after warm-up frames; per case the median
(IQR) GPU ms of the frame and of the passes that read float inputs, the ratio imageLoad /
texelFetch, and a verdict that says "faster" or "slower" only where the IQRs do not overlap. The
images are the same either way (tests/test_input_fetch.py).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import benchmark_arguments, device_header  # noqa: E402

CASES = {
    "hiz_mirror": dict(layers=1, method="hiz", sampling="mirror", rays_per_pixel=1, reuse_radius=1),
    "thesis": dict(layers=4, rays_per_pixel=4, stride=4.0, downscale=2, max_steps=250, method="linear",
                   sampling="vndf"),
}
PASSES = ("total", "lighting", "trace_hiz", "trace_linear", "resolve", "composite")
FETCHES = ("texelFetch", "imageLoad")


def main(argv=None) -> int:
    ap = benchmark_arguments(__doc__, repeats=9)
    ap.set_defaults(width=1920, height=1080, scenes=["hall", "spheres_and_boxes"])
    args = ap.parse_args(argv)
    import ssrlab
    from ssrlab.lab import timing

    renderers = {"texelFetch": ssrlab.Renderer(args.device, input_fetch="texelFetch")}
    print(device_header(renderers["texelFetch"]))
    try:
        renderers["imageLoad"] = ssrlab.Renderer(args.device, input_fetch="imageLoad")
    except ValueError as e:  # e.g. NVIDIA's GL: 8 image units a compute shader, 10 needed
        print(f"imageLoad cannot run on this device, nothing to compare: {e}")
        return 0
    print(f"{args.width}x{args.height}; GPU ms, median (IQR) of {args.repeats} frames per side, the sides alternating")
    print("| scene | case | pass | texelFetch | imageLoad | imageLoad / texelFetch | verdict |")
    print("|---|---|---|---|---|---|---|")
    for scene_name in args.scenes:
        scene = ssrlab.scenes.load(scene_name)
        for case, kw in CASES.items():
            s = ssrlab.Settings(width=args.width, height=args.height, **kw)
            for r in renderers.values():
                for _ in range(2):
                    r.render(scene, settings=s).timings
            runs = {f: [] for f in FETCHES}
            for _ in range(args.repeats):
                for f, r in renderers.items():
                    runs[f].append(r.render(scene, settings=s).timings)
            for p in PASSES:
                if p not in runs["texelFetch"][0]:
                    continue
                q = {f: np.percentile([t[p] for t in runs[f]], [25, 50, 75]) for f in FETCHES}
                t, i = q["texelFetch"], q["imageLoad"]
                # (median, q1, q3): the interquartile ranges apart, or no verdict
                apart = timing.verdict((t[1], t[0], t[2]), (i[1], i[0], i[2]))
                verdict = ("too few frames to judge (--repeats < 5)" if args.repeats < 5
                           else f"imageLoad {apart}" if apart != "undecided" else "no verdict (IQRs overlap)")
                print(f"| {scene_name} | {case} | {p} | {t[1]:.3f} ({t[0]:.3f}-{t[2]:.3f}) | "
                      f"{i[1]:.3f} ({i[0]:.3f}-{i[2]:.3f}) | {i[1] / t[1]:.2f} | {verdict} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
