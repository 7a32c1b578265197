"""Helpers shared by the benchmark scripts: options, device header and the protocol are
ssrlab.lab.protocol's (re-exported here), the timing statistics ssrlab.lab.timing's."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from ssrlab.lab.protocol import arguments, device_header, open_renderer  # noqa: E402,F401  (one protocol)
from ssrlab.lab.timing import median_timings  # noqa: E402,F401  (the scripts' timing protocol)


# SSR alone, the hybrid and pure BVH, each with the BVH passes' default traced shadows and with the
# frame's shadow map (bvh_shadows="map"): the frames benchmarks/hybrid.py and mitsuba_crosscheck.py score.
HYBRID_FRAMES = {
    "SSR only": dict(),
    "SSR + BVH fallback": dict(fallback="bvh"),
    "SSR + BVH fallback, bvh_shadows='map'": dict(fallback="bvh", bvh_shadows="map"),
    "pure BVH": dict(method="bvh"),
    "pure BVH, bvh_shadows='map'": dict(method="bvh", bvh_shadows="map"),
}


def frame_ms(renderer, scene, settings, repeats: int) -> tuple[float, float, float]:
    """The frame's GPU ms, (median, min, max) of `repeats` renders after 2 warm-ups (compilation,
    uploads and first builds are never timed)."""
    from ssrlab.lab.timing import median_range

    for _ in range(2):
        renderer.render(scene, settings=settings)
    return median_range(renderer.render(scene, settings=settings).timings["total"] for _ in range(repeats))


def benchmark_arguments(doc: str, repeats: int | None = None, *, settings: bool = False) -> argparse.ArgumentParser:
    """The options every benchmark takes (ssrlab.lab.protocol.arguments): image size, scenes,
    device, --records (and repeats when timed; --set with `settings`, for the scripts whose
    configurations all take it: the A/B tools parse their own sides')."""
    return arguments(doc, repeats, settings=settings)


def ab_scenes(renderer, scenes: dict, settings, parts, repeats: int, header: str) -> None:
    """Times `parts` (keys of Frame.timings) of two scenes, {"texture": a, "factor": b} style (the
    feature on, then off), rendered interleaved `repeats` times each after one untimed render of
    each (compilation, uploads), and prints per part both medians with min-max and interquartile
    range, the paired ratio first / second and ssrlab.lab.timing's verdict (undecided where the
    ranges overlap)."""
    import numpy as np

    from ssrlab.lab.timing import median_range, paired, verdict

    (name_a, a_scene), (name_b, b_scene) = scenes.items()
    for scene in (a_scene, b_scene):
        renderer.render(scene, settings=settings)  # first use
    times = {name: {p: [] for p in parts} for name in scenes}
    for _ in range(repeats):
        for name, scene in scenes.items():
            t = renderer.render(scene, settings=settings).timings
            for p in parts:
                times[name][p].append(t[p])
    print(f"{header}, {repeats} interleaved repeats; ms (median [min, max], IQR)")

    def iqr(v):
        return float(np.subtract(*np.percentile(v, [75, 25])))

    for p in parts:
        a, b = times[name_a][p], times[name_b][p]
        ma, mb = median_range(a), median_range(b)
        print(f"{p:11s} {name_a} {ma[0]:8.2f} [{ma[1]:.2f}, {ma[2]:.2f}] IQR {iqr(a):.2f} | {name_b} {mb[0]:8.2f} "
              f"[{mb[1]:.2f}, {mb[2]:.2f}] IQR {iqr(b):.2f} | {name_a}/{name_b} {np.median(paired(a, b)):.3f} "
              f"-> {name_a} {verdict(mb, ma)}")
