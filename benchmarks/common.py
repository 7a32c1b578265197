"""Helpers shared by the benchmark scripts: timing protocol and device header."""

from __future__ import annotations

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
