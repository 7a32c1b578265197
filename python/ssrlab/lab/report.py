"""Reporting a sweep: Pareto fronts of error against time, the rows as CSV and JSON, the plots.

Works on the rows ssrlab.lab.run.sweep returns (or ssrlab.lab.plan.load_sweep's sweep wrote),
with no renderer: a results folder can be re-reported anywhere.
"""

from __future__ import annotations

import csv
import io as _stdio
import json
import math
import textwrap
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
        cols.update(dict.fromkeys(k for k in r if k != "samples"))  # each time's runs: rows.json only
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
        w.writerow({k: ("" if v is None else v) for k, v in r.items() if k != "samples"})
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


# Marker shapes, one per (scene, view[, device]); colours, one per technique group.
MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*", "<", ">")
# Above this ratio between the largest and smallest time, the time axis is logarithmic.
LOG_TIME_SPAN = 20.0
FIGURE_SIZE = (7.0, 4.5)  # inches
FIGURE_DPI = 120
# The plot's key lists at most this many points by number (a larger sweep: rows.csv has them all).
KEY_ROWS = 60
SIDE_WIDTH, MAX_SIDE_WIDTH = 3.0, 7.0  # inches: the legend and the key beside the plot
KEY_FONT = 6.5  # points
FRONT_LABEL_CHARS = 48  # a front point's label on the plot is wrapped at this many characters


def _value_text(v) -> str:
    if isinstance(v, (list, tuple)):
        return "+".join(map(_value_text, v)) or "none"
    if isinstance(v, float):
        return f"{v:g}"
    return str(v)


def _categorical(values) -> bool:
    """True unless every value is a number (a technique is named by choices, tuned by numbers);
    None (a user pass's parameter in a row without that pass) counts as neither."""
    return not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values if v is not None)


def _named_settings(rows: list[dict]) -> list[str]:
    """varying_settings without user_params, whose entries have a column each ('<pass>.<param>')."""
    return [k for k in varying_settings(rows) if k != "user_params"]


def technique_settings(rows: list[dict]) -> list[str]:
    """The varying settings (varying_settings) that name a technique rather than tune it: those
    whose values are not all numbers (method, glossy, sampling, user_passes, skip, ...). Rays,
    layers, steps, a user pass's parameters and other numbers tune a technique."""
    return [k for k in _named_settings(rows) if _categorical([r.get(SETTINGS_PREFIX + k) for r in rows])]


def point_labels(rows: list[dict], *, places: bool = True) -> list[str]:
    """Each row named by the settings that differ between the rows (varying_settings, in field
    order, user parameters last): 'method=hiz, rays_per_pixel=4, glossy=cone'. Rows of several
    scenes or views add them where they differ ('scene=hall, view=low, ...'; not with
    places=False); a user pass's parameter is named only in the rows that have it. '' for every
    row when nothing differs."""
    keys = [k for k in FRONT_GROUP_KEYS if places and len({str(r.get(k)) for r in rows}) > 1]
    settings = _named_settings(rows)
    # A user pass's parameter is left out of the rows that do not have it (another technique's).
    return [", ".join([f"{k}={r.get(k)}" for k in keys]
                      + [f"{k}={_value_text(r.get(SETTINGS_PREFIX + k))}" for k in settings
                         if r.get(SETTINGS_PREFIX + k) is not None]) for r in rows]


def technique_groups(rows: list[dict]) -> list[str]:
    """Each row's technique group: its values of technique_settings ('method=hiz, glossy=cone');
    '' for every row when no such setting varies (one group)."""
    keys = technique_settings(rows)
    return [", ".join(f"{k}={_value_text(r.get(SETTINGS_PREFIX + k))}" for k in keys) for r in rows]


def _spread(r: dict, key: str, lo: str, hi: str) -> tuple[float, float] | None:
    """(below, above) the row's value of `key`: its distance to the columns `lo` and `hi`."""
    v, a, b = _number(r, key), _number(r, lo), _number(r, hi)
    if v is None or a is None or b is None:
        return None
    return max(v - a, 0.0), max(b - v, 0.0)


def _label_front(ax, fronts: dict, rows: list[dict], labels: list[str], time_key: str, error_key: str) -> None:
    """Names each front point on the plot by its settings (its scene and view are its marker): the
    text turned toward the inside of the axes, moved to another side of its point where it would
    cover a label already placed or another point, or leave the axes."""
    from matplotlib.transforms import Bbox

    renderer = ax.figure.canvas.get_renderer()
    frame = ax.get_window_extent(renderer)
    to_axes = ax.transData + ax.transAxes.inverted()
    by_id = {id(r): i for i, r in enumerate(rows)}
    # The labels placed so far and every point (a few pixels around it): what a label should not cover.
    placed = [Bbox.from_extents(x - 4, y - 4, x + 4, y + 4) for r in rows
              if (t := _number(r, time_key)) is not None and (e := _number(r, error_key)) is not None
              for x, y in [ax.transData.transform((t, e))]]
    for front in fronts.values():
        for r in front:
            text = "\n".join(textwrap.wrap(labels[by_id[id(r)]], FRONT_LABEL_CHARS)) if id(r) in by_id else ""
            if not text:
                continue
            t, e = _number(r, time_key), _number(r, error_key)
            fx, fy = to_axes.transform((t, e))
            inward_x = (-7, "right") if fx > 0.55 else (7, "left")
            inward_y = [(-9, "top"), (9, "bottom")] if fy > 0.5 else [(9, "bottom"), (-9, "top")]
            outward_x = (-inward_x[0], "left" if inward_x[1] == "right" else "right")
            tries = [(x, (dy * k, va)) for k in (1.0, 2.6, 4.2) for x in (inward_x, outward_x) for dy, va in inward_y]
            # The first place that stays inside the axes and covers nothing, else the one that
            # covers least (leaving the axes counts as covering two).
            best = None
            for (dx, ha), (dy, va) in tries:
                note = ax.annotate(text, (t, e), xytext=(dx, dy), textcoords="offset points", ha=ha, va=va,
                                   fontsize=6.5, zorder=4,
                                   bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.8))
                box = note.get_window_extent(renderer)
                inside = frame.contains(box.x0, box.y0) and frame.contains(box.x1, box.y1)
                cost = 2 * (not inside) + sum(box.overlaps(b) for b in placed)
                if best is None or cost < best[0]:
                    if best is not None:
                        best[1].remove()
                    best = (cost, note, box)
                else:
                    note.remove()
                if cost == 0:
                    break
            placed.append(best[2])


def plot_error_vs_time(rows: list[dict], time_key: str = "time_frame_ms", error_key: str = "thesis_error", *,
                       fronts: dict[tuple, list[dict]] | None = None):
    """Error against time of a sweep's rows, as a matplotlib Figure (what ``ssrlab bench`` saves as
    error_vs_time.png and a notebook shows for ``bench.sweep``'s rows; fig.savefig(path) writes it):

    - every point numbered (the row's index) and named in the key beside the plot by the
      settings that differ between the rows (point_labels);
    - one colour per technique group (technique_groups), one marker per scene and view (and
      device, where several timed the rows);
    - each point's time spread drawn as a bar from the fastest to the slowest repeat
      (<time_key>_min to _max), and for sequences the error's range over the scored frames
      (<error_key>_frame_min to _max) where the rows carry it;
    - each (scene, view)'s Pareto front as a step line, its points labelled on the plot.
    """
    # A Figure of its own on an Agg canvas, not pyplot's: no backend is switched and nothing is left
    # open (a notebook keeps its inline backend and shows the figure once, as a cell's value).
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    if fronts is None:
        fronts = pareto_fronts(rows, time_key, error_key)
    labels = point_labels(rows)
    techniques = technique_groups(rows)
    by_device = len({r.get(DEVICE_KEY) for r in rows}) > 1
    places = [front_group(r) + ((r.get(DEVICE_KEY),) if by_device else ()) for r in rows]
    place_index = {p: k for k, p in enumerate(dict.fromkeys(places))}
    technique_index = {t: k for k, t in enumerate(dict.fromkeys(techniques))}
    on_front = {id(r) for f in fronts.values() for r in f}
    numbers = [r.get("index", i) for i, r in enumerate(rows)]

    key_lines = [f"{n}: {label or 'the only configuration'}" + ("  (front)" if id(r) in on_front else "")
                 for n, label, r in zip(numbers, labels, rows)]
    shown = key_lines[:KEY_ROWS]
    if len(key_lines) > KEY_ROWS:
        shown.append(f"... {len(key_lines) - KEY_ROWS} more (rows.csv, column index)")
    # The side panel as wide as its longest line of monospace text (a character is about 0.6 em),
    # within [SIDE_WIDTH, MAX_SIDE_WIDTH]; longer lines are wrapped.
    chars = int((MAX_SIDE_WIDTH - 0.3) * 72 / (0.6 * KEY_FONT))
    shown = [w for line in shown for w in (textwrap.wrap(line, chars, subsequent_indent="    ") or [""])]
    side_width = min(MAX_SIDE_WIDTH, max(SIDE_WIDTH, max(map(len, shown)) * 0.6 * KEY_FONT / 72 + 0.3))
    height = max(FIGURE_SIZE[1], 0.13 * len(shown) + 0.2 * (len(technique_index) + len(place_index)) + 1.5)
    fig = Figure(figsize=(FIGURE_SIZE[0] + side_width, height), dpi=FIGURE_DPI)
    FigureCanvasAgg(fig)
    ax, side = fig.subplots(1, 2, gridspec_kw={"width_ratios": [FIGURE_SIZE[0], side_width]})
    spreads = 0
    for i, r in enumerate(rows):
        t, e = _number(r, time_key), _number(r, error_key)
        if t is None or e is None:
            continue
        colour = f"C{technique_index[techniques[i]] % 10}"
        marker = MARKERS[place_index[places[i]] % len(MARKERS)]
        xerr = _spread(r, time_key, time_key + "_min", time_key + "_max")
        yerr = _spread(r, error_key, error_key + "_frame_min", error_key + "_frame_max")
        if xerr is not None or yerr is not None:
            spreads += xerr is not None
            ax.errorbar([t], [e], xerr=None if xerr is None else [[xerr[0]], [xerr[1]]],
                        yerr=None if yerr is None else [[yerr[0]], [yerr[1]]], fmt="none", ecolor=colour,
                        elinewidth=1.0, capsize=3, alpha=0.8, zorder=2)
        ax.scatter([t], [e], marker=marker, color=colour, edgecolors="black" if id(r) in on_front else "none",
                   linewidths=0.8, s=36, zorder=3)
        ax.annotate(str(numbers[i]), (t, e), xytext=(-4, -4), textcoords="offset points", ha="right", va="top",
                    fontsize=6, color="0.25")
    positive = [t for r in rows if (t := _number(r, time_key)) is not None and t > 0]
    if positive and max(positive) / min(positive) > LOG_TIME_SPAN:
        ax.set_xscale("log")
    for front in fronts.values():
        pts = [(_number(r, time_key), _number(r, error_key)) for r in front]
        ax.step(*zip(*pts), where="post", color="0.3", linewidth=0.8, linestyle="--", zorder=1)
    repeats = sorted({r.get("repeats") for r in rows if isinstance(r.get("repeats"), int)})
    how = (f"median of {'/'.join(map(str, repeats))} repeat{'s' if repeats != [1] else ''}" if repeats
           else "median")
    ax.set_xlabel(f"{time_key} ({how}; bar: fastest to slowest repeat)" if spreads else time_key)
    ax.set_ylabel(error_key)
    ax.set_title(f"{error_key} against {time_key}")
    ax.grid(True, alpha=0.3)
    handles = [Line2D([], [], marker="o", linestyle="none", color=f"C{k % 10}", label=t or "every configuration")
               for t, k in technique_index.items()]
    if len(place_index) > 1:
        for p, k in place_index.items():
            name = str(p[0]) if p[1] in (None, "default") else f"{p[0]} / {p[1]}"
            handles.append(Line2D([], [], marker=MARKERS[k % len(MARKERS)], linestyle="none", color="0.4",
                                  label=name + (f" on {p[2]}" if by_device else "")))
    handles.append(Line2D([], [], color="0.3", linestyle="--", linewidth=0.8,
                          label="Pareto front" + (" of each" if len(fronts) > 1 else "") + " (labelled)"))
    side.axis("off")
    fig.tight_layout()
    _label_front(ax, fronts, rows, point_labels(rows, places=False), time_key, error_key)
    # The legend (colour: technique group; marker: scene and view) atop the side panel, the key of
    # every point below it.
    legend = side.legend(handles=handles, fontsize="small", loc="upper left", bbox_to_anchor=(0.0, 1.0),
                         borderaxespad=0.0, title="colour: " + (", ".join(technique_settings(rows)) or "one group"),
                         title_fontsize="small", alignment="left")
    fig.canvas.draw()
    bottom = side.transAxes.inverted().transform(legend.get_window_extent().get_points())[0][1]
    key = side.text(0.0, bottom - 0.03, "points: index and the settings that differ\n" + "\n".join(shown),
                    va="top", ha="left", fontsize=KEY_FONT, family="monospace", transform=side.transAxes)
    # Wider where the key's longest line needs it: the plot keeps its size in inches.
    fig.canvas.draw()
    right = max(key.get_window_extent().x1, legend.get_window_extent().x1) / fig.dpi + 0.15
    old = fig.get_figwidth()
    if right > old:
        boxes = [a.get_position() for a in (ax, side)]
        fig.set_figwidth(right)
        for a, b in zip((ax, side), boxes):
            a.set_position([b.x0 * old / right, b.y0, b.width * old / right, b.height])
    return fig


def _plot_error_vs_time(path: Path, rows: list[dict], fronts: dict[tuple, list[dict]], time_key: str,
                        error_key: str) -> None:
    plot_error_vs_time(rows, time_key, error_key, fronts=fronts).savefig(path, format="png")


class SweepRows(list):
    """A sweep's rows (a list of dicts, what bench.sweep returns) that a notebook shows as their
    error against time (plot_error_vs_time, frame time against thesis_error)."""

    def _repr_png_(self) -> bytes | None:
        try:
            fig = plot_error_vs_time(list(self))
        except ValueError:  # no row has both a time and an error: nothing to draw
            return None
        buf = _stdio.BytesIO()
        fig.savefig(buf, format="png")
        return buf.getvalue()


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
    error_vs_time.png      every row numbered and named by the settings that differ (plot_error_vs_time):
                           a colour per technique group, a marker per scene and view, each point's
                           time spread as a bar, the Pareto fronts as lines with their points labelled
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
           "technique_settings", "point_labels", "technique_groups", "plot_error_vs_time", "SweepRows",
           "result_names", "write_results"]
