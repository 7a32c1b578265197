"""Helpers shared by the benchmark scripts: options, device header; the timing protocol is
ssrlab.lab.timing's."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from ssrlab.lab.timing import median_timings  # noqa: E402,F401  (the scripts' timing protocol)


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
