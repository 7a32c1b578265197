"""Statistics of repeated timings, one place for every sweep and benchmark script.

A time measured once says little on a shared machine (llvmpipe on busy cores) or a GPU whose
clock changes: every figure ssrlab reports is the median of repeats with their spread beside it,
so that a difference can be told from noise.

    spread(values)          min, median, max and interquartile range (a sweep row's columns)
    median_range(values)    (median, min, max): the triple the benchmark scripts print
    verdict(base, now)      "faster" / "slower" only where two (median, min, max) ranges are apart
    paired(a, b)            the ratio of each repeat's pair (both sides timed at the same moments)
    median_timings(...)     median GPU milliseconds per pass of repeated renders after warm-ups
"""

from __future__ import annotations

import statistics

import numpy as np

# Suffixes of the spread columns beside every time column (see spread).
SPREAD_SUFFIXES = ("_min", "_max", "_iqr")


def time_column(column: str) -> str:
    """The time column a spread column belongs to (gpu_resolve_ms_iqr -> gpu_resolve_ms), else itself."""
    for suffix in SPREAD_SUFFIXES:
        if column.endswith(suffix) and column[:-len(suffix)].endswith("_ms"):
            return column[:-len(suffix)]
    return column


def spread(values: list[float]) -> dict[str, float | None]:
    """min, median, max and interquartile range (75th - 25th percentile, numpy's linear
    interpolation) of repeated timings; iqr is None for a single value (no spread measured)."""
    v = np.asarray([float(x) for x in values], np.float64)
    if v.size == 0:
        raise ValueError("spread: no values")
    iqr = float(np.percentile(v, 75) - np.percentile(v, 25)) if v.size > 1 else None
    return {"min": float(v.min()), "median": float(np.median(v)), "max": float(v.max()), "iqr": iqr}


def with_spread(row: dict, column: str, values: list[float]) -> None:
    """Puts the median of `values` under `column` and its spread under column_min, _max, _iqr."""
    st = spread(values)
    row[column] = st["median"]
    for suffix in SPREAD_SUFFIXES:
        row[column + suffix] = st[suffix[1:]]


def median_range(values) -> tuple[float, float, float]:
    """(median, min, max) of repeated timings."""
    values = list(values)
    if not values:
        raise ValueError("median_range: no values")
    return statistics.median(values), min(values), max(values)


def verdict(base, now) -> str:
    """'faster' / 'slower' when the (median, min, max) ranges of `now` and `base` are apart (no
    repeat of one overlaps the other's), else 'undecided': a difference within the noise is no
    difference."""
    (_, blo, bhi), (_, clo, chi) = base, now
    if chi < blo:
        return "faster"
    if clo > bhi:
        return "slower"
    return "undecided"


def paired(numerators, denominators) -> list[float]:
    """The ratio of each repeat's pair of timings (two sides measured at the same moments, so that a
    change of the machine's load between repeats cancels)."""
    return [a / b for a, b in zip(numerators, denominators)]


def median_timings(renderer, scene, settings, *, repeats: int = 7, warmup: int = 2) -> dict[str, float]:
    """Median GPU milliseconds per timing key over `repeats` renders after `warmup` renders (the
    warm-ups compile the shader variants and upload the scene, which no timing should include)."""
    for _ in range(warmup):
        renderer.render(scene, settings=settings)
    runs = [renderer.render(scene, settings=settings).timings for _ in range(repeats)]
    return {k: statistics.median(r[k] for r in runs) for k in runs[0]}


__all__ = ["SPREAD_SUFFIXES", "time_column", "spread", "with_spread", "median_range", "verdict", "paired",
           "median_timings"]
