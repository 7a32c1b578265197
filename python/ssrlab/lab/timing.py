"""Statistics of repeated timings, one place for every sweep and benchmark script.

A time measured once says little on a shared machine (llvmpipe on busy cores) or a GPU whose
clock changes: every figure ssrlab reports is the median of repeats with their spread beside it,
so that a difference can be told from noise.

    spread(values)          min, median, max and interquartile range (a sweep row's columns)
    median_range(values)    (median, min, max): the triple the benchmark scripts print
    verdict(base, now)      "faster" / "slower" only where two (median, min, max) ranges are apart
    paired(a, b)            the ratio of each repeat's pair (both sides timed at the same moments)
    median_timings(...)     median GPU milliseconds per pass of repeated renders after warm-ups
    timing_doubt(rows, ...) why the times of sweep rows cannot bear a verdict (None when they can)
    target_verdict(...)     "met" / "not met" for repeated ratios against a target, or why it cannot tell
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
    """Puts the median of `values` under `column`, its spread under column_min, _max, _iqr and the
    values themselves under ``row["samples"][column]`` (what a benchmark record keeps)."""
    st = spread(values)
    row[column] = st["median"]
    row.setdefault("samples", {})[column] = [float(x) for x in values]
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


# -- when a timing can be judged ---------------------------------------------------------------------
TOO_SMALL = "too small to judge"
# Fewer timed runs than this measure no usable spread (an interquartile range of 1-2 values is noise).
MIN_JUDGED_REPEATS = 3
# Times below this are dominated by GPU timer resolution and per-pass overheads, whatever the spread.
MIN_JUDGED_MS = 1.0


def _time(row: dict, keys) -> tuple[float, float | None]:
    """(median, spread) of one time column, or of the sum of several (spreads add up); the
    spread is the interquartile range of the repeats (None when not measured)."""
    keys = (keys,) if isinstance(keys, str) else tuple(keys)
    present = [k for k in keys if row.get(k) is not None]
    median = float(sum(row[k] for k in present))
    iqrs = [row.get(k + "_iqr") for k in present]
    return median, (None if not present or any(v is None for v in iqrs) else float(sum(iqrs)))


def timing_doubt(rows: list[dict], keys, *, pairwise: bool = False) -> str | None:
    """None when the times of `rows` under `keys` (a column, or columns summed) can be judged;
    else why not. Judged means: every row timed at least MIN_JUDGED_REPEATS times, every
    median at least MIN_JUDGED_MS, and the medians' differences beyond the repeats' spread:
    with pairwise=True every consecutive pair differs by more than the sum of the two IQRs (a
    comparison); otherwise the span of the medians exceeds twice the largest IQR (a trend)."""
    if not rows:
        return "no timings"
    repeats = min(int(r.get("repeats") or 1) for r in rows)
    if repeats < MIN_JUDGED_REPEATS:
        return (f"{repeats} timed run(s) per configuration, so no spread to tell a difference from noise; "
                f"at least {MIN_JUDGED_REPEATS} needed")
    times = [_time(r, keys) for r in rows]
    if any(iqr is None for _, iqr in times):
        return "the spread of the repeats was not recorded"
    low = min(t for t, _ in times)
    if low < MIN_JUDGED_MS:
        return f"times down to {low:.2g} ms, below the {MIN_JUDGED_MS:g} ms a GPU timer resolves reliably"
    if pairwise:
        for (a, ia), (b, ib) in zip(times, times[1:]):
            if abs(a - b) <= ia + ib:
                return (f"{a:.3g} vs {b:.3g} ms differ by no more than the repeats' spread "
                        f"(IQR {ia:.2g} + {ib:.2g} ms)")
        return None
    span = max(t for t, _ in times) - low
    widest = max(i for _, i in times)
    if span <= 2 * widest:
        return f"the times span {span:.2g} ms, within twice the repeats' spread (IQR up to {widest:.2g} ms)"
    return None


def target_verdict(values, op: str, goal: float) -> str:
    """"met", "not met", or why the repeats cannot tell, for a ratio measured once per repeat
    (each from one pair of timings taken at the same moments) against a target `op goal`
    (op "<=" or ">="): met when the middle half of the values (25th to 75th percentile) meets
    it, not met when the middle half misses it, else too small to judge."""
    if op not in ("<=", ">="):
        raise ValueError(f"target_verdict: op must be '<=' or '>=', got {op!r}")
    v = np.asarray([float(x) for x in values], np.float64)
    if v.size < MIN_JUDGED_REPEATS:
        return f"{TOO_SMALL}: {v.size} value(s), at least {MIN_JUDGED_REPEATS} needed"
    if not np.all(np.isfinite(v)):
        return f"{TOO_SMALL}: a repeat gave no finite value"
    q1, q3 = (float(q) for q in np.percentile(v, [25, 75]))
    best, worst = (q1, q3) if op == "<=" else (q3, q1)
    meets = (lambda x: x <= goal) if op == "<=" else (lambda x: x >= goal)
    if meets(worst):
        return "met"
    if not meets(best):
        return "not met"
    return f"{TOO_SMALL}: the middle half of the repeats, {q1:.3g}-{q3:.3g}, straddles the target"


__all__ = ["SPREAD_SUFFIXES", "time_column", "spread", "with_spread", "median_range", "verdict", "paired",
           "median_timings", "TOO_SMALL",
           "MIN_JUDGED_REPEATS", "MIN_JUDGED_MS", "timing_doubt", "target_verdict"]
