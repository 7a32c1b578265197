"""Benchmark results as records: one format, appended as JSON lines, read back, compared.

A record is one figure of one benchmark, measured once per sample:

    {"benchmark": "frame_breakdown", "params": {"scene": "hall", "case": "hiz_mirror", ...},
     "metric": "total", "unit": "ms", "samples": [2.91, 2.88, 2.95],
     "device": "llvmpipe (LLVM 15.0.6, 256 bits)", "driver": "Mesa, OpenGL 4.5 (Core Profile) Mesa 22.3.6",
     "commit": "095fe50a1b", "date": "2025-01-01T12:00:00+00:00", "command": "python benchmarks/..."}

(optionally "better": "lower" or "higher", which way a figure improves; times are "lower"). A
benchmark appends its records to ``<folder>/<benchmark>.jsonl``, where ``<folder>`` is
``benchmarks/results/<device-slug>`` for run_all.py's runs (slug() of the renderer string).
Samples are the raw values, never a median: whoever reads the records computes the spread.

    Recorder(benchmark, folder, renderer)   fills device, driver, commit, date and command itself
    read_records(folder | "git:<commit>:<folder>")   every record of a folder, or of a commit's
    table(records, rows, columns)           a Markdown table: median [25th-75th percentile] per cell
    ab_table(records, side, a, b, rows)     an A/B table: both sides, B/A and the verdict of each figure
    compare(old, new)                       each figure present in both: NEW/OLD and a verdict
    history(folder, benchmark, metric, params)   a figure at each commit that changed the records
"""

from __future__ import annotations

import datetime
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

# The checkout the figures come from: this package's own source tree where it runs from one, else
# the folder the command runs in (an installed package lies in site-packages, whose enclosing git
# repository, if any, is not the project's).
_SOURCE = Path(__file__).resolve().parents[3]
REPO = _SOURCE if (_SOURCE / ".git").exists() and (_SOURCE / "benchmarks").is_dir() else Path.cwd()
TIME_UNITS = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}
FIELDS = ("benchmark", "params", "metric", "unit", "samples", "device", "driver", "commit", "date", "command")
# Environment variables that route a benchmark's records (run_all.py sets them for every script).
RECORDS_ENV, QUICK_ENV = "SSRLAB_RECORDS", "SSRLAB_RECORDS_QUICK"


def slug(text: str) -> str:
    """A device's folder name: its renderer string lower-cased, runs of other characters as '-'."""
    return re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-")[:60]


def git_commit(where: Path | str = REPO) -> str:
    """The checkout's commit, "+dirty" when it has uncommitted changes (what the figures come from);
    $SSRLAB_COMMIT where set (a copy of the tree without its .git, e.g. on a device machine)."""
    if os.environ.get("SSRLAB_COMMIT"):
        return os.environ["SSRLAB_COMMIT"]

    def git(*a):
        return subprocess.run(["git", "-C", str(where), *a], capture_output=True, text=True, timeout=60)

    try:
        head = git("rev-parse", "--short=10", "HEAD")
    except (OSError, subprocess.SubprocessError):
        return "unknown (no git)"
    if head.returncode:
        return "unknown (not a git checkout)"
    dirty = git("status", "--porcelain", "--untracked-files=no").stdout.strip()
    return head.stdout.strip() + ("+dirty" if dirty else "")


def command_line() -> str:
    """This process's command as a person would type it from the repository's root."""
    argv = list(sys.argv)
    if argv and Path(argv[0]).name == "__main__.py" and Path(argv[0]).parent.name == "ssrlab":
        return " ".join(["ssrlab", *argv[1:]])  # python -m ssrlab
    if argv and argv[0].endswith(".py"):
        p = Path(argv[0]).resolve()
        try:
            argv[0] = str(p.relative_to(REPO))
        except ValueError:
            argv[0] = str(p)
        return " ".join(["python", *argv])
    return " ".join(["ssrlab" if a.endswith("ssrlab") else a for a in argv[:1]] + argv[1:])


def is_timing(record: dict) -> bool:
    return record.get("unit") in TIME_UNITS


def better(record: dict) -> str:
    """Which way the figure improves: the record's "better", else "lower" (times, errors)."""
    return record.get("better") or "lower"


def _plain(value):
    """JSON-safe parameters and samples (numpy scalars, tuples, paths)."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Path):
        return str(value)
    return value


class Recorder:
    """Makes and keeps a benchmark's records, and appends them to ``folder/<benchmark>.jsonl``
    when there is a folder (the argument, else $SSRLAB_RECORDS; none: kept in memory only, for
    the tables the script prints). `quick` (else $SSRLAB_RECORDS_QUICK=1) puts quick: true in
    every record's params: a run for checking, not for quoting."""

    def __init__(self, benchmark: str, folder=None, renderer=None, *, quick: bool | None = None,
                 command: str | None = None):
        self.benchmark = benchmark
        folder = folder if folder is not None else os.environ.get(RECORDS_ENV) or None
        self.folder = Path(folder) if folder is not None else None
        self.quick = bool(os.environ.get(QUICK_ENV) == "1") if quick is None else quick
        info = renderer.info if renderer is not None else {}
        self.device = info.get("renderer", "unknown")
        self.driver = (f"{info.get('vendor', '?')}, OpenGL {info.get('gl_version', '?')}" if info else "unknown")
        self.commit = git_commit()
        self.command = command or command_line()
        self.records: list[dict] = []

    def add(self, params: dict, metric: str, unit: str, samples, *, better: str | None = None,
            **extra) -> dict:
        """One figure's record (written at once where there is a folder); returns it."""
        samples = [float(v) for v in (samples if np.ndim(samples) else [samples])]
        params = _plain(dict(params))
        if self.quick:
            params["quick"] = True
        rec = {"benchmark": self.benchmark, "params": params, "metric": metric, "unit": unit,
               "samples": samples, "device": self.device, "driver": self.driver, "commit": self.commit,
               "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
               "command": self.command}
        if better is not None:
            if better not in ("lower", "higher"):
                raise ValueError(f"Recorder.add: better must be 'lower' or 'higher', got {better!r}")
            rec["better"] = better
        rec.update(_plain(extra))
        self.records.append(rec)
        if self.folder is not None:
            self.folder.mkdir(parents=True, exist_ok=True)
            with open(self.folder / f"{self.benchmark}.jsonl", "a") as f:
                f.write(json.dumps(rec, allow_nan=True) + "\n")
        return rec

    def find(self, metric: str | None = None, **params) -> list[dict]:
        """This run's records of `metric` whose params hold every given key = value."""
        return select(self.records, metric, **params)


def select(records, metric: str | None = None, **params) -> list[dict]:
    return [r for r in records if (metric is None or r["metric"] == metric)
            and all(r["params"].get(k) == v for k, v in params.items())]


# -- reading -------------------------------------------------------------------------------------------
def _parse_lines(text: str, where: str) -> list[dict]:
    out = []
    for i, line in enumerate(text.splitlines(), 1):
        line = line.strip()
        if not line:
            continue
        try:
            rec = json.loads(line)
        except ValueError as e:
            raise ValueError(f"{where}:{i}: not a JSON record ({e})") from None
        missing = [k for k in ("benchmark", "params", "metric", "unit", "samples") if k not in rec]
        if missing:
            raise ValueError(f"{where}:{i}: a record without {', '.join(missing)}")
        out.append(rec)
    return out


def read_records(source) -> list[dict]:
    """Every record of a results folder: its ``*.jsonl`` files, or, where it has none, those of
    its sub-folders (one per device). ``git:<commit>:<folder>`` reads a commit's committed
    records through ``git show`` (the folder relative to the repository's root)."""
    text = str(source)
    if text.startswith("git:"):
        try:
            _, commit, folder = text.split(":", 2)
        except ValueError:
            raise ValueError(f"read_records: expected git:<commit>:<folder>, got {text!r}") from None
        folder = folder.strip("/")
        listed = subprocess.run(["git", "-C", str(REPO), "ls-tree", "-r", "--name-only", commit, "--", folder],
                                capture_output=True, text=True, timeout=60)
        if listed.returncode:
            raise ValueError(f"read_records: {text}: {listed.stderr.strip()}")
        files = sorted(p for p in listed.stdout.splitlines() if p.endswith(".jsonl"))
        direct = [p for p in files if "/" not in p[len(folder) + 1:]]
        out = []
        for p in direct or files:
            shown = subprocess.run(["git", "-C", str(REPO), "show", f"{commit}:{p}"], capture_output=True,
                                   text=True, timeout=60)
            out += _parse_lines(shown.stdout, f"{commit}:{p}")
        if not files:
            raise FileNotFoundError(f"read_records: no .jsonl records under {folder} at {commit}")
        return out
    folder = Path(source)
    if folder.is_file():
        return _parse_lines(folder.read_text(), str(folder))
    if not folder.is_dir():
        raise FileNotFoundError(f"read_records: no folder {folder}")
    files = sorted(folder.glob("*.jsonl")) or sorted(folder.glob("*/*.jsonl"))
    if not files:
        raise FileNotFoundError(f"read_records: no .jsonl records in {folder}")
    return [r for f in files for r in _parse_lines(f.read_text(), str(f))]


def figure_key(record: dict) -> tuple:
    """What makes two records the same figure: benchmark, parameters and metric."""
    return (record["benchmark"], json.dumps(record["params"], sort_keys=True), record["metric"])


def latest(records) -> dict[tuple, dict]:
    """Each figure's latest record (by date, then order: a later run's append wins)."""
    out = {}
    for r in sorted(enumerate(records), key=lambda ir: (str(ir[1].get("date", "")), ir[0])):
        out[figure_key(r[1])] = r[1]
    return out


# -- tables -----------------------------------------------------------------------------------------------
def summary(samples) -> dict:
    """n, median, 25th and 75th percentile, min and max of a record's samples."""
    v = np.asarray(samples, np.float64)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return {"n": 0, "median": float("nan"), "p25": float("nan"), "p75": float("nan"),
                "min": float("nan"), "max": float("nan")}
    q1, med, q3 = np.percentile(v, [25, 50, 75])
    return {"n": int(v.size), "median": float(med), "p25": float(q1), "p75": float(q3),
            "min": float(v.min()), "max": float(v.max())}


def _num(x: float, digits: int) -> str:
    if not np.isfinite(x):
        return "-"
    if x != 0 and (abs(x) >= 1e6 or abs(x) < 10 ** -digits):
        return f"{x:.3g}"
    return f"{x:.{digits}f}"


def cell(samples, digits: int = 2, spread: str = "iqr") -> str:
    """A table cell: the median, and with several samples its [25th-75th percentile] (spread
    "iqr") or [min-max] (spread "range")."""
    s = summary(samples)
    if s["n"] == 0:
        return "-"
    if s["n"] == 1:
        return _num(s["median"], digits)
    lo, hi = (s["p25"], s["p75"]) if spread == "iqr" else (s["min"], s["max"])
    return f"{_num(s['median'], digits)} [{_num(lo, digits)}-{_num(hi, digits)}]"


def markdown(header: list[str], rows: list[list[str]]) -> str:
    """A Markdown table of strings."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def table(records, rows: list[str], columns: str = "metric", *, digits: int = 2, spread: str = "iqr",
          order: list | None = None) -> str:
    """A Markdown table rendered from records: one row per combination of the `rows` params
    (in the records' order), one column per value of `columns` (a param's name, or "metric"),
    each cell the median of the figure's samples with its spread (cell()). Figures of a row
    without a column's value leave it "-"; `order` fixes and filters the columns."""
    records = list(records)

    def col_of(r):
        v = r["metric"] if columns == "metric" else r["params"].get(columns)
        return v if columns != "metric" else f"{v} ({r['unit']})" if r.get("unit") else v

    cols = list(order) if order is not None else list(dict.fromkeys(col_of(r) for r in records))
    if order is not None and columns == "metric":  # `order` names metrics: add their units
        units = {r["metric"]: r.get("unit") for r in records}
        cols = [f"{c} ({units[c]})" if units.get(c) else c for c in cols if c in units]
    grid: dict[tuple, dict] = {}
    for r in records:
        key = tuple(r["params"].get(k) for k in rows)
        grid.setdefault(key, {})[col_of(r)] = r["samples"]
    body = [[("-" if v is None else str(v)) for v in key] + [cell(cells[c], digits, spread) if c in cells else "-"
                                                              for c in cols] for key, cells in grid.items()]
    return markdown([*rows, *map(str, cols)], body)


def spread_note(records, spread: str = "iqr") -> str:
    """The line under a table saying what its cells are."""
    ns = sorted({summary(r["samples"])["n"] for r in records})
    n = f"{ns[0]}" if len(ns) == 1 else f"{ns[0]}-{ns[-1]}"
    what = "25th-75th percentile" if spread == "iqr" else "min-max"
    return f"cells: median [{what}] of {n} sample(s)"



def ab_table(records, side: str, a, b, rows=(), *, digits: int = 2, spread: str = "iqr", units: bool = True,
             words: dict | None = None) -> str:
    """A Markdown table of an A/B measurement rendered from records: every figure measured on
    both sides (two records of one metric whose params differ only by `side`, one `a`, one `b`),
    as the `rows` params, the metric, each side's cell, B/A and the verdict of B against A
    (figure_verdict(): faster / slower / same / undecided, better / worse for what is not a
    time). B/A is the median [spread] of the per-sample ratios where both sides have as many
    samples (the rounds of an interleaved run pair them), else the ratio of the medians."""
    pairs: dict[tuple, dict] = {}
    for r in records:
        v = r["params"].get(side)
        if v not in (a, b):
            continue
        rest = {k: x for k, x in r["params"].items() if k != side}
        pairs.setdefault((json.dumps(rest, sort_keys=True, default=str), r["metric"]), {})[v] = r
    body = []
    for (_, metric), d in pairs.items():
        if a not in d or b not in d:
            continue
        ra, rb = d[a], d[b]
        verdict, ratio, _, _ = figure_verdict(ra, rb)
        sa, sb = np.asarray(ra["samples"], np.float64), np.asarray(rb["samples"], np.float64)
        if sa.size == sb.size and sa.size > 1 and np.all(sa != 0):
            over = cell(sb / sa, 3, spread)
        else:
            over = _num(ratio, 3)
        unit = f" ({ra['unit']})" if ra.get("unit") and units else ""
        said = (words or {}).get(verdict, f"{b} {verdict}")
        body.append([("-" if ra["params"].get(k) is None else str(ra["params"].get(k))) for k in rows]
                    + [metric + unit, cell(sa, digits, spread), cell(sb, digits, spread), over, said])
    return markdown([*rows, "metric", str(a), str(b), f"{b} / {a}", "verdict"], body)

# -- comparing ------------------------------------------------------------------------------------------
SAME_BAND = 0.02     # NEW/OLD within 2 % either way is the same figure
CONFIDENCE = 0.95    # the bootstrap interval of the ratio of medians
BOOTSTRAP = 2000
MIN_SAMPLES = 3


def ratio_interval(old, new, *, rounds: int = BOOTSTRAP, confidence: float = CONFIDENCE,
                   seed: int = 0) -> tuple[float, float, float]:
    """(NEW/OLD of the medians, and the bootstrap interval of that ratio): each side resampled
    with replacement `rounds` times, the ratio of the resamples' medians, its central
    `confidence` share."""
    a, b = np.asarray(old, np.float64), np.asarray(new, np.float64)
    rng = np.random.default_rng(seed)
    ma = np.median(a[rng.integers(0, a.size, (rounds, a.size))], axis=1)
    mb = np.median(b[rng.integers(0, b.size, (rounds, b.size))], axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = mb / ma
    tail = 100 * (1 - confidence) / 2
    lo, hi = np.percentile(r, [tail, 100 - tail])
    return float(np.median(b) / np.median(a)), float(lo), float(hi)


def figure_verdict(old: dict, new: dict, band: float = SAME_BAND) -> tuple[str, float, float, float]:
    """(verdict, ratio, low, high) of one figure, NEW against OLD.

    The rule: the ratio of the medians NEW/OLD and its 95 % bootstrap interval (ratio_interval).
    Where the whole interval lies within the band [1 - band, 1 + band] (2 %): "same". Where it
    lies wholly above 1 + band: "slower" for a time (a lower-is-better figure: "worse"), wholly
    below 1 - band: "faster" ("better"); for a higher-is-better figure the other way round.
    Otherwise, or with fewer than 3 samples a side: "undecided" - except that identical samples
    are "same", and figures of one sample each (a deterministic count or error) are judged by
    their ratio alone against the band.
    """
    a = np.asarray(old["samples"], np.float64)
    b = np.asarray(new["samples"], np.float64)
    a, b = a[np.isfinite(a)], b[np.isfinite(b)]
    if a.size == 0 or b.size == 0:
        return "undecided", float("nan"), float("nan"), float("nan")
    ma, mb = float(np.median(a)), float(np.median(b))
    if a.size == b.size and np.array_equal(np.sort(a), np.sort(b)):
        return "same", 1.0, 1.0, 1.0  # the very same samples (a run against itself)
    if ma == mb:
        ratio = 1.0
    elif ma == 0:
        return "undecided", float("inf"), float("nan"), float("nan")
    else:
        ratio = mb / ma
    if min(a.size, b.size) < MIN_SAMPLES:
        deterministic = np.ptp(a) == 0 and np.ptp(b) == 0
        if not deterministic:
            return "undecided", ratio, float("nan"), float("nan")
        lo = hi = ratio
    else:
        ratio, lo, hi = ratio_interval(a, b)
        if ma == mb:
            ratio = 1.0
    if 1 - band <= lo and hi <= 1 + band:
        return "same", ratio, lo, hi
    up, down = lo > 1 + band, hi < 1 - band
    if not (up or down):
        return "undecided", ratio, lo, hi
    lower_better = better(new) == "lower"
    good = down if lower_better else up
    if is_timing(new):
        return ("faster" if good else "slower"), ratio, lo, hi
    return ("better" if good else "worse"), ratio, lo, hi


def compare(old_records, new_records, band: float = SAME_BAND) -> list[dict]:
    """Every figure present in both (the latest record of each), with both sides' summaries,
    NEW/OLD of the medians, its interval and figure_verdict()'s verdict."""
    old, new = latest(old_records), latest(new_records)
    out = []
    for key in [k for k in new if k in old]:
        o, n = old[key], new[key]
        verdict, ratio, lo, hi = figure_verdict(o, n, band)
        out.append({"benchmark": key[0], "params": n["params"], "metric": key[2], "unit": n.get("unit"),
                    "old": summary(o["samples"]), "new": summary(n["samples"]), "ratio": ratio, "low": lo,
                    "high": hi, "verdict": verdict, "timing": is_timing(n)})
    return out


def compare_table(rows: list[dict]) -> str:
    def params(p):
        return ", ".join(f"{k}={v}" for k, v in p.items())

    def side(s):
        return cell([s["median"]]) if s["n"] == 1 else \
            f"{_num(s['median'], 3)} [{_num(s['p25'], 3)}-{_num(s['p75'], 3)}] n={s['n']}"

    body = [[r["benchmark"], params(r["params"]), f"{r['metric']} ({r['unit']})", side(r["old"]), side(r["new"]),
             _num(r["ratio"], 3) + ("" if not np.isfinite(r["low"]) or r["low"] == r["high"]
                                    else f" [{_num(r['low'], 3)}-{_num(r['high'], 3)}]"), r["verdict"]]
            for r in rows]
    return markdown(["benchmark", "params", "metric", "OLD median [p25-p75]", "NEW median [p25-p75]",
                     "NEW/OLD [95 % interval]", "verdict"], body)


# -- a figure over commits ----------------------------------------------------------------------------
def commits_of(folder: str, last: int = 20) -> list[str]:
    """The commits that changed the committed records under `folder` (relative to the repository's
    root), oldest first, the last `last` of them."""
    log = subprocess.run(["git", "-C", str(REPO), "log", "--format=%h", f"-{last}", "--", str(folder)],
                         capture_output=True, text=True, timeout=60)
    if log.returncode:
        raise ValueError(f"history: git log -- {folder}: {log.stderr.strip()}")
    return list(reversed(log.stdout.split()))


def history(folder: str, benchmark: str, metric: str, params: dict | None = None,
            commits: list[str] | None = None) -> list[dict]:
    """A figure over commits: for each commit (default: commits_of(folder)), the latest record of
    every figure of `benchmark` and `metric` whose params hold `params`, read from that commit's
    committed records. One row per (commit, figure): commit, the record's own commit and date, its
    params, and summary() of its samples. A commit without such a record, or whose record is the one
    an earlier commit already had (its records changed elsewhere), has no row."""
    params = params or {}
    folder = str(folder).strip("/")
    rows, seen = [], {}
    for c in commits if commits is not None else commits_of(folder):
        try:
            recs = read_records(f"git:{c}:{folder}")
        except (ValueError, FileNotFoundError):
            continue
        chosen = [r for r in recs if r["benchmark"] == benchmark and r["metric"] == metric
                  and all(r["params"].get(k) == v for k, v in params.items())]
        for key, r in latest(chosen).items():
            same = (r.get("date"), r.get("commit"), json.dumps(r["samples"]))
            if seen.get(key) == same:
                continue
            seen[key] = same
            rows.append({"commit": c, "recorded_at": r.get("commit"), "date": r.get("date"), "params": r["params"],
                         "unit": r.get("unit"), **summary(r["samples"])})
    if not rows:
        raise ValueError(f"history: no record of {benchmark} / {metric} with {params or 'any params'} under "
                         f"{folder} at the commits looked at")
    return rows


def history_table(rows: list[dict]) -> str:
    """history()'s rows as a Markdown table: a figure's median [25th-75th percentile] at each commit."""
    varying = sorted({k for r in rows for k in r["params"] if len({json.dumps(x["params"].get(k)) for x in rows}) > 1})
    body = [[r["commit"], f"{str(r['date'])[:16].replace('T', ' ')} at {r['recorded_at']}",
             ", ".join(f"{k}={r['params'].get(k)}" for k in varying) or "–",
             f"{_num(r['median'], 3)} [{_num(r['p25'], 3)}-{_num(r['p75'], 3)}]", str(r["n"])] for r in rows]
    return markdown(["commit", "recorded", "figure", f"median [p25-p75] ({rows[0]['unit']})", "samples"], body)


def plot_history(rows: list[dict], path, title: str = "") -> None:
    """history()'s rows drawn: each figure's median over the commits, its 25th-75th percentile as
    error bars; written to `path` (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    commits = list(dict.fromkeys(r["commit"] for r in rows))
    varying = sorted({k for r in rows for k in r["params"] if len({json.dumps(x["params"].get(k)) for x in rows}) > 1})
    figures = {}
    for r in rows:
        label = ", ".join(f"{k}={r['params'].get(k)}" for k in varying) or "figure"
        figures.setdefault(label, []).append(r)
    fig, ax = plt.subplots(figsize=(max(4.0, 0.6 * len(commits) + 2.0), 3.2))
    for label, rs in figures.items():
        x = [commits.index(r["commit"]) for r in rs]
        y = [r["median"] for r in rs]
        err = [[r["median"] - r["p25"] for r in rs], [r["p75"] - r["median"] for r in rs]]
        ax.errorbar(x, y, yerr=err, marker="o", capsize=3, label=label)
    ax.set_xticks(range(len(commits)), commits, rotation=45, ha="right")
    ax.set_ylabel(rows[0]["unit"] or "")
    ax.set_title(title, fontsize=9)
    if len(figures) > 1:
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


__all__ = ["FIELDS", "TIME_UNITS", "RECORDS_ENV", "QUICK_ENV", "slug", "git_commit", "command_line", "Recorder",
           "select", "read_records", "figure_key", "latest", "summary", "cell", "markdown", "table", "spread_note",
           "ab_table",
           "SAME_BAND", "ratio_interval", "figure_verdict", "compare", "compare_table", "is_timing", "better",
           "commits_of", "history", "history_table", "plot_history"]
