"""Reporting a sweep: Pareto fronts of error against time, the rows as CSV and JSON, the plots.

Works on the rows ssrlab.lab.run.sweep returns (or ssrlab.lab.plan.load_sweep's sweep wrote),
with no renderer: a results folder can be re-reported anywhere.
"""

from __future__ import annotations

import csv
import io as _stdio
import json
import math
from pathlib import Path

from .plan import SETTINGS_FIELDS, SETTINGS_PREFIX
from .timing import time_column

# -- Pareto front --------------------------------------------------------------------------------------
def _number(row: dict, key: str) -> float | None:
    v = row.get(key)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        return None
    return float(v)


# Columns whose rows never share a Pareto front: a time budget only means something within
# one scene seen from one view, timed on one device.
FRONT_GROUP_KEYS = ("scene", "view")
# The device a row was timed on: its OpenGL renderer string (the hardware model; several GPUs
# of one model count as one device, their times being comparable).
DEVICE_KEY = "gl_renderer"


def front_group(row: dict) -> tuple:
    """The (scene, view) a row belongs to (missing columns count as one value)."""
    return tuple(row.get(k) for k in FRONT_GROUP_KEYS)


def _better_direction(error_key: str) -> float:
    """+1 where lower is better (errors), -1 for similarities (psnr, ssim)."""
    from ..truth.metrics import HIGHER_IS_BETTER

    return -1.0 if error_key in HIGHER_IS_BETTER else 1.0


def _error_argument(error_key: str, error: str | None) -> str:
    if error is not None:
        if error_key != "thesis_error" and error_key != error:
            raise ValueError(f"pass the metric as error= or error_key=, not both (got error={error!r} and "
                             f"error_key={error_key!r})")
        return error
    return error_key


def pareto_front(rows: list[dict], time_key: str = "time_frame_ms", error_key: str = "thesis_error", *,
                 error: str | None = None) -> list[dict]:
    """The rows no other row beats in both time and error, sorted by time: the best error
    reachable within each time budget.

    `error` (or error_key) is any metric column: errors (thesis_error, rmse, flip_ldr,
    flip_hdr, their _reflective ones, ...) where lower is better, or the similarities of
    ssrlab.metrics.HIGHER_IS_BETTER (psnr, ssim, ...) where higher is better.

    A row is on the front when every faster-or-equal row is worse. Of rows with equal time
    and error the first (in `rows` order) is kept. Rows without a finite number under either
    key are left out; ValueError if no row has both. All rows must be of one scene and view,
    timed on one device (ValueError otherwise: a front across scenes compares unlike images,
    across devices unlike clocks; see pareto_fronts).
    """
    error_key = _error_argument(error_key, error)
    groups = {front_group(r) for r in rows}
    if len(groups) > 1:
        raise ValueError(f"pareto_front: the rows mix {len(groups)} (scene, view) pairs "
                         f"({', '.join(map(str, sorted(groups, key=str)))}); a front is per scene and view: "
                         f"use pareto_fronts(rows)")
    devices = {r.get(DEVICE_KEY) for r in rows}
    if len(devices) > 1:
        raise ValueError(f"pareto_front: the rows were timed on {len(devices)} devices "
                         f"({', '.join(sorted(map(str, devices)))}); a front is per device: use pareto_fronts(rows)")
    sign = _better_direction(error_key)
    scored = [(t, sign * e, i) for i, r in enumerate(rows)
              if (t := _number(r, time_key)) is not None and (e := _number(r, error_key)) is not None]
    if not scored:
        raise ValueError(f"pareto_front: no row has finite numbers under time_key={time_key!r} and "
                         f"error_key={error_key!r}")
    front, best = [], math.inf
    for t, e, i in sorted(scored):
        if e < best:
            front.append(rows[i])
            best = e
    return front


def pareto_fronts(rows: list[dict], time_key: str = "time_frame_ms",
                  error_key: str = "thesis_error", *, error: str | None = None) -> dict[tuple, list[dict]]:
    """One Pareto front (pareto_front) per (scene, view), in the rows' order of first
    appearance: {(scene, view): front}. Where the rows were timed on several devices
    (gl_renderer) the fronts are per (scene, view, device) and so are the keys: times of two
    devices never share a front. Groups whose rows have no finite time and error are left
    out; ValueError if no group has any."""
    error_key = _error_argument(error_key, error)
    by_device = len({r.get(DEVICE_KEY) for r in rows}) > 1
    groups: dict[tuple, list[dict]] = {}
    for r in rows:
        key = front_group(r) + ((r.get(DEVICE_KEY),) if by_device else ())
        groups.setdefault(key, []).append(r)
    fronts = {}
    for key, rs in groups.items():
        if any(_number(r, time_key) is not None and _number(r, error_key) is not None for r in rs):
            fronts[key] = pareto_front(rs, time_key, error_key)
    if not fronts:
        raise ValueError(f"pareto_fronts: no row has finite numbers under time_key={time_key!r} and "
                         f"error_key={error_key!r}")
    return fronts


# -- writing results ------------------------------------------------------------------------------------
def varying_settings(rows: list[dict]) -> list[str]:
    """Settings fields (without the prefix) whose value differs between rows, in field order."""
    out = []
    user = sorted({k[len(SETTINGS_PREFIX):] for r in rows for k in r if k.startswith(SETTINGS_PREFIX) and "." in k})
    for name in (*SETTINGS_FIELDS, *user):
        values = {json.dumps(r.get(SETTINGS_PREFIX + name)) for r in rows}
        if len(values) > 1:
            out.append(name)
    return out


def _columns(rows: list[dict]) -> list[str]:
    """Every column of any row, in first-seen order, the gpu_<pass>_ms columns (which differ
    between configurations, e.g. one per layer) kept together and sorted."""
    cols: dict[str, None] = {}
    for r in rows:
        cols.update(dict.fromkeys(r))
    gpu = sorted(c for c in cols if c.startswith("gpu_") and time_column(c).endswith("_ms"))
    out: list[str] = []
    for c in cols:
        if c not in gpu:
            out.append(c)
        elif gpu[0] not in out:  # the first timing column seen: the whole block goes here
            out.extend(gpu)
    return out


def _csv_text(rows: list[dict]) -> str:
    buf = _stdio.StringIO()
    w = csv.DictWriter(buf, fieldnames=_columns(rows), restval="", lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: ("" if v is None else v) for k, v in r.items()})
    return buf.getvalue()


def _json_safe(v):
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def result_names(rows_or_keys) -> list[str]:
    """The files write_results writes: rows.csv, rows.json, pareto.csv, error_vs_time.png and,
    when exactly one setting varies, <setting>.png. Takes rows, or the list of varying keys."""
    keys = rows_or_keys
    if rows_or_keys and isinstance(rows_or_keys[0], dict):
        keys = varying_settings(rows_or_keys)
    names = ["rows.csv", "rows.json", "pareto.csv", "error_vs_time.png"]
    if len(keys) == 1:
        names.append(f"{keys[0]}.png")
    return names


# Marker shapes, one per scene (colours follow matplotlib's default cycle).
MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*", "<", ">")
# Above this ratio between the largest and smallest time, the time axis is logarithmic.
LOG_TIME_SPAN = 20.0
FIGURE_SIZE = (7.0, 4.5)  # inches
FIGURE_DPI = 120


def _plot_error_vs_time(path: Path, rows: list[dict], fronts: dict[tuple, list[dict]], time_key: str,
                        error_key: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=FIGURE_SIZE, dpi=FIGURE_DPI)
    by_device = len({r.get(DEVICE_KEY) for r in rows}) > 1
    groups: dict[tuple, list[dict]] = {}
    for r in rows:
        groups.setdefault(front_group(r) + ((r.get(DEVICE_KEY),) if by_device else ()), []).append(r)
    for k, (key, rs) in enumerate(groups.items()):
        scene, view = key[:2]
        label = str(scene) if view in (None, "default") else f"{scene} / {view}"
        if by_device:
            label += f" on {key[2]}"
        pts = [(t, e) for r in rs if (t := _number(r, time_key)) is not None and (e := _number(r, error_key))
               is not None]
        if pts:
            ax.scatter(*zip(*pts), marker=MARKERS[k % len(MARKERS)], color=f"C{k % 10}", label=label, zorder=3)
        if key in fronts:  # each scene's (and view's) own front, in its colour
            fx = [_number(r, time_key) for r in fronts[key]]
            fy = [_number(r, error_key) for r in fronts[key]]
            ax.step(fx, fy, where="post", color=f"C{k % 10}", linewidth=1.0, zorder=2,
                    label="Pareto front of each" if k == 0 else None)
    positive = [t for r in rows if (t := _number(r, time_key)) is not None and t > 0]
    if positive and max(positive) / min(positive) > LOG_TIME_SPAN:
        ax.set_xscale("log")
    ax.set_xlabel(time_key)
    ax.set_ylabel(error_key)
    ax.set_title(f"{error_key} against {time_key}")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(path, format="png")
    plt.close(fig)


def _plot_against_setting(path: Path, rows: list[dict], key: str, time_key: str, error_key: str) -> None:
    """Error and time against one swept setting, one line per (scene, view): the thesis's
    Figs. 3.3-3.10. Non-numeric settings (method, sampling) are placed at even spacing."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    column = SETTINGS_PREFIX + key
    values = list(dict.fromkeys(r[column] for r in rows))
    numeric = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)
    position = (lambda v: v) if numeric else (lambda v: values.index(v))
    fig, (ax_e, ax_t) = plt.subplots(1, 2, figsize=(2 * FIGURE_SIZE[0], FIGURE_SIZE[1]), dpi=FIGURE_DPI)
    groups: dict[tuple, list[dict]] = {}
    for r in rows:
        groups.setdefault((r.get("scene", "?"), r.get("view", "default")), []).append(r)
    for k, ((scene, view), rs) in enumerate(groups.items()):
        label = scene if view == "default" else f"{scene} / {view}"
        style = dict(marker=MARKERS[k % len(MARKERS)], color=f"C{k % 10}", label=label)
        for ax, metric in ((ax_e, error_key), (ax_t, time_key)):
            pts = sorted((position(r[column]), y) for r in rs if (y := _number(r, metric)) is not None)
            if pts:
                ax.plot(*zip(*pts), **style)
    for ax, metric in ((ax_e, error_key), (ax_t, time_key)):
        ax.set_xlabel(key)
        ax.set_ylabel(metric)
        ax.grid(True, alpha=0.3)
        if not numeric:
            ax.set_xticks(range(len(values)), [str(v) for v in values])
        elif all(isinstance(v, int) for v in values):
            ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax_e.set_title(f"{error_key} against {key}")
    ax_t.set_title(f"{time_key} against {key}")
    ax_e.legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(path, format="png")
    plt.close(fig)


def write_results(rows: list[dict], folder, *, time_key: str = "time_frame_ms", error_key: str = "thesis_error",
                  overwrite: bool = False) -> list[Path]:
    """Writes a sweep's results into `folder` and returns the files written:

    rows.csv, rows.json    every row (the columns of the module documentation)
    pareto.csv             the Pareto front of every (scene, view) (pareto_fronts), one after another
    error_vs_time.png      every row, one marker and colour per scene and view, its Pareto front as a line
    <setting>.png          when exactly one setting varies between rows: error and time against it

    Never replaces a file that ssrlab did not write (ssrlab.io.OutputFolder; overwrite=True
    to force): FileExistsError, before anything is written.
    """
    from ..io import OutputFolder

    if not rows:
        raise ValueError("write_results: rows is empty")
    for key, name in ((time_key, "time_key"), (error_key, "error_key")):
        if not any(key in r for r in rows):
            raise ValueError(f"write_results: {name}={key!r} is not a column of the rows")
    fronts = pareto_fronts(rows, time_key, error_key)
    front = [r for f in fronts.values() for r in f]
    keys = varying_settings(rows)
    names = result_names(keys)
    out = OutputFolder(folder, overwrite=overwrite)
    out.check(names)
    safe_rows = [{k: _json_safe(v) for k, v in r.items()} for r in rows]
    written = [
        out.write("rows.csv", lambda p: p.write_text(_csv_text(rows))),
        out.write("rows.json", lambda p: p.write_text(json.dumps(safe_rows, indent=1, allow_nan=False))),
        out.write("pareto.csv", lambda p: p.write_text(_csv_text(front))),
        out.write("error_vs_time.png", lambda p: _plot_error_vs_time(p, rows, fronts, time_key, error_key)),
    ]
    if len(keys) == 1:
        written.append(out.write(f"{keys[0]}.png",
                                 lambda p: _plot_against_setting(p, rows, keys[0], time_key, error_key)))
    return written


__all__ = ["FRONT_GROUP_KEYS", "DEVICE_KEY", "front_group", "pareto_front", "pareto_fronts", "varying_settings",
           "result_names", "write_results"]
