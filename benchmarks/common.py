"""Helpers shared by the benchmark scripts of every genre folder (each puts the repository's root on
sys.path and imports benchmarks.common, so that it runs from any cwd): options, device header and the protocol are
ssrlab.lab.protocol's (re-exported here); the hybrid's frames and the A/B of two scenes measured
through the protocol's rounds."""

from __future__ import annotations

import argparse

from ssrlab.lab.protocol import arguments, device_header, open_renderer  # noqa: F401  (one protocol)


# SSR alone, the hybrid and pure BVH, each with the BVH passes' default traced shadows and with the
# frame's shadow map (bvh_shadows="map"): the frames benchmarks/studies/hybrid.py and
# benchmarks/accuracy/mitsuba_crosscheck.py score.
HYBRID_FRAMES = {
    "SSR only": dict(),
    "SSR + BVH fallback": dict(fallback="bvh"),
    "SSR + BVH fallback, bvh_shadows='map'": dict(fallback="bvh", bvh_shadows="map"),
    "pure BVH": dict(method="bvh"),
    "pure BVH, bvh_shadows='map'": dict(method="bvh", bvh_shadows="map"),
}


def benchmark_arguments(doc: str, repeats: int | None = None, *, settings: bool = False) -> argparse.ArgumentParser:
    """The options every benchmark takes (ssrlab.lab.protocol.arguments): image size, scenes,
    device, --records (and repeats when timed; --set with `settings`, for the scripts whose
    configurations all take it: the A/B tools parse their own sides')."""
    return arguments(doc, repeats, settings=settings)


def ab_scenes(bench, renderer, scenes: dict, settings, parts, header: str, params: dict | None = None) -> None:
    """Times `parts` (keys of Frame.timings) of two scenes, {"texture": a, "factor": b} style (the
    feature on, then off), rendered interleaved round by round after the protocol's warm-up
    rounds (compilation, uploads: ssrlab.lab.protocol.Bench.rounds); records each part of each
    side (param "scene_variant") and prints the A/B table rendered from the records, with the
    paired ratio second / first and the verdict of the second against the first."""
    def render(scene):
        return lambda: renderer.render(scene, settings=settings).timings

    times = bench.rounds({name: render(scene) for name, scene in scenes.items()})
    for name in scenes:
        bench.record_all({**(params or {}), "scene_variant": name}, times[name], "ms", parts)
    print(f"{header}, {bench.repeats} interleaved rounds after {bench.warmup} warm-up rounds; GPU ms")
    a, b = scenes
    bench.print_ab("scene_variant", a, b)
