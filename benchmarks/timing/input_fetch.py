"""How the passes read their float inputs: Renderer(input_fetch="texelFetch") against "imageLoad",
A/B in one run.

    python benchmarks/timing/input_fetch.py [--width 1920 --height 1080] [--device gpu] [--repeats 9]

Two renderers on the same device, one per input fetch (shaders/lib/input_fetch.glsl), render the
same scene and settings alternately, frame by frame (the protocol's rounds, after its warm-up
rounds); per case the GPU ms of the frame and of the passes that read float inputs are records,
and the table rendered from them gives both sides, the per-round ratio imageLoad / texelFetch
and the verdict of imageLoad against texelFetch (records.figure_verdict: faster, slower, same or
undecided at this noise). The
images are the same either way (tests/test_input_fetch.py).
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402

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
    from ssrlab.lab.protocol import Bench

    renderers = {"texelFetch": open_renderer(args, input_fetch="texelFetch")}
    bench = Bench("input_fetch", args, renderers["texelFetch"])
    try:
        renderers["imageLoad"] = ssrlab.Renderer(args.device, input_fetch="imageLoad")
    except ValueError as e:  # e.g. NVIDIA's GL: 8 image units a compute shader, 10 needed
        print(f"imageLoad cannot run on this device, nothing to compare: {e}")
        return 0
    print(f"{args.width}x{args.height}; GPU ms of {args.repeats} rounds after {bench.warmup} warm-up rounds, the "
          f"sides alternating; pass: the pass's GPU ms")
    for scene_name in args.scenes:
        scene = ssrlab.scenes.load(scene_name)
        for case, kw in CASES.items():
            s = ssrlab.Settings(width=args.width, height=args.height, **kw)
            runs = bench.rounds({f: (lambda r=r: r.render(scene, settings=s).timings) for f, r in renderers.items()})
            for f in FETCHES:
                bench.record_all(dict(scene=scene_name, case=case, fetch=f, width=args.width, height=args.height),
                                 runs[f], "ms", PASSES)
    # Fewer than 5 frames a side give no spread worth a verdict, whatever the samples say.
    few = {v: "too few frames to judge (--repeats < 5)" for v in ("faster", "slower", "same", "undecided")}
    bench.print_ab("fetch", *FETCHES, rows=("scene", "case"), units=False, words=few if args.repeats < 5 else None)
    return 0


if __name__ == "__main__":
    sys.exit(main())
