"""Helpers shared by the benchmark scripts: timing protocol and device header."""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))


def median_timings(renderer, scene, settings, *, repeats: int = 7, warmup: int = 2) -> dict[str, float]:
    """Median GPU milliseconds per timing key over `repeats` renders after `warmup` renders."""
    for _ in range(warmup):
        renderer.render(scene, settings=settings)
    runs = [renderer.render(scene, settings=settings).timings for _ in range(repeats)]
    return {k: statistics.median(r[k] for r in runs) for k in runs[0]}


def device_header(renderer) -> str:
    i = renderer.info
    return f"device: {i['renderer']} ({i['device']}), {i['vendor']}, OpenGL {i['gl_version']}"


def benchmark_arguments(doc: str, repeats: int | None = None) -> argparse.ArgumentParser:
    """The options every benchmark takes: image size, scenes, device (and repeats when timed)."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=360)
    ap.add_argument("--scenes", nargs="+", default=["spheres_and_boxes", "hall"])
    ap.add_argument("--device", default="auto", choices=("auto", "gpu", "cpu"))
    if repeats is not None:
        ap.add_argument("--repeats", type=int, default=repeats)
    return ap


def open_renderer(args):
    """The benchmark's Renderer, with the device line every benchmark prints first."""
    import ssrlab

    renderer = ssrlab.Renderer(args.device)
    print(device_header(renderer))
    return renderer
