"""The benchmarks' one protocol: options, device header, warm-up, repeats, interleaving, records,
tables and verdicts. Every benchmark script that measures something goes through here.

    arguments(doc, repeats=N)      the options every benchmark takes (size, scenes, device, repeats,
                                   --set, --records); the docstring is its --help
    parse_set(items)               --set FIELD=VALUE items as a dict of settings (the CLI's parser too)
    device_header(renderer)        the first line every benchmark prints
    Bench(name, args, renderer)    a run: its Recorder and the protocol's counts (warm-up, repeats)
      .rounds(configs)             every configuration measured once per round, rounds after the
                                   warm-up rounds recorded: interleaved, so a slow spell of a shared
                                   machine falls on every configuration alike
      .frames(renderer, scene, settings_by_name)    the same for renders: Frame.timings per round
      .calls(named_calls)          the same for CPU-side calls: wall milliseconds per round
      .record(...) / .table(...)   the run's records, and Markdown tables rendered from them
      .print_ab(side, a, b)        an A/B table of the records (records.ab_table) with verdicts
    goal_verdict(values, op, goal) met / not met / undecided at this noise, from per-round ratios

The statistics are ssrlab.lab.timing's; the record format and the tables ssrlab.lab.records'.
"""

from __future__ import annotations

import argparse
import json
import time
from typing import Callable

import numpy as np

from . import records as _records
from .timing import MIN_JUDGED_REPEATS, target_verdict

WARMUP = 2  # untimed rounds before the timed ones: uploads, driver caches, first builds


def parse_value(text: str):
    """A --set value: JSON where it parses (numbers, booleans, lists), Python's True and False,
    else the string."""
    if text in ("True", "False"):
        return text == "True"
    try:
        return json.loads(text)
    except ValueError:
        return text


def parse_set(items) -> dict:
    """--set FIELD=VALUE items (repeatable) as {field: value}; ValueError naming a bad item."""
    changes = {}
    for item in items or []:
        if "=" not in item:
            raise ValueError(f"--set expects FIELD=VALUE, got {item!r}")
        key, value = item.split("=", 1)
        changes[key.strip()] = parse_value(value.strip())
    return changes


def device_header(renderer) -> str:
    i = renderer.info
    return f"device: {i['renderer']} ({i['device']}), {i['vendor']}, OpenGL {i['gl_version']}"


def arguments(doc: str, repeats: int | None = None, *, scenes=("spheres_and_boxes", "hall"),
              size=(640, 360), settings: bool = True) -> argparse.ArgumentParser:
    """The options every benchmark takes: image size, scenes, device, --set (unless `settings` is
    False), where its records go (and repeats when it times something)."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--width", type=int, default=size[0])
    ap.add_argument("--height", type=int, default=size[1])
    ap.add_argument("--scenes", nargs="+", default=list(scenes))
    ap.add_argument("--device", default="auto", choices=("auto", "gpu", "cpu"))
    if settings:
        ap.add_argument("--set", action="append", metavar="FIELD=VALUE", default=[],
                        help="a Settings field every configuration takes (repeatable)")
    ap.add_argument("--records", metavar="FOLDER",
                    help=f"append this run's records to FOLDER/<benchmark>.jsonl (default: ${_records.RECORDS_ENV} "
                         "where set, else none are written)")
    ap.add_argument("--records-quick", action="store_true",
                    help="mark the records quick: true (a run for checking, not for quoting)")
    if repeats is not None:
        ap.add_argument("--repeats", type=int, default=repeats)
    return ap


def open_renderer(args, **options):
    """The benchmark's Renderer (Renderer options beside the device), with the device line every
    benchmark prints first."""
    import ssrlab

    renderer = ssrlab.Renderer(args.device, **options)
    print(device_header(renderer), flush=True)
    return renderer


def goal_verdict(values, op: str, goal: float) -> str:
    """met / not met / undecided at this noise, from per-round values (ratios of two renders of
    one round) against `op goal`: met where the middle half of the rounds meets it (timing's
    target_verdict), not met where it misses it, else undecided with the middle half printed."""
    values = [float(v) for v in values]
    if len(values) < MIN_JUDGED_REPEATS:
        return f"undecided: {len(values)} round(s), at least {MIN_JUDGED_REPEATS} needed"
    v = target_verdict(values, op, goal)
    if v in ("met", "not met"):
        return v
    q1, q3 = np.percentile(values, [25, 75])
    return f"undecided at this noise (the middle half of the rounds, {q1:.2f}-{q3:.2f}x, straddles {goal:g}x)"


class Bench:
    """One benchmark run under the protocol: its records (Recorder), its warm-up and repeats."""

    def __init__(self, name: str, args=None, renderer=None, *, repeats: int | None = None, warmup: int = WARMUP):
        self.name = name
        self.args = args
        self.repeats = int(repeats if repeats is not None else getattr(args, "repeats", 3) or 1)
        self.warmup = warmup
        self.settings = parse_set(getattr(args, "set", None))
        quick = True if getattr(args, "records_quick", False) else None
        self.recorder = _records.Recorder(name, getattr(args, "records", None), renderer, quick=quick)

    # -- measuring ----------------------------------------------------------------------------------
    def rounds(self, configs: dict[str, Callable[[], dict]], *, repeats: int | None = None,
               warmup: int | None = None) -> dict[str, dict[str, list[float]]]:
        """Calls every configuration's measure() once per round, `warmup` untimed rounds then
        `repeats` recorded ones; returns {config: {metric: [one value per round]}} (a metric a
        round did not report is left out of that round)."""
        repeats = self.repeats if repeats is None else repeats
        warmup = self.warmup if warmup is None else warmup
        out = {name: {} for name in configs}
        for rnd in range(warmup + repeats):
            for name, measure in configs.items():
                values = measure()
                if rnd >= warmup:
                    for k, v in values.items():
                        out[name].setdefault(k, []).append(float(v))
        return out

    def frames(self, renderer, scene, settings: dict, *, repeats: int | None = None, warmup: int | None = None,
               keep: Callable | None = None, wall: bool = False) -> dict[str, dict[str, list[float]]]:
        """Frame.timings of every named Settings, interleaved round by round (rounds()); with
        `wall`, also the render() call's wall milliseconds ("render_wall"); `keep(name, frame)`
        sees each recorded round's frame (to read counts from it) before it is released."""
        state = {"round": 0}

        def measure(name, s):
            def run():
                t0 = time.perf_counter()
                f = renderer.render(scene, settings=s)
                values = dict(f.timings)
                if wall:
                    values["render_wall"] = (time.perf_counter() - t0) * 1e3
                if keep is not None:
                    keep(name, f)
                return values
            return run

        return self.rounds({n: measure(n, s) for n, s in settings.items()}, repeats=repeats, warmup=warmup)

    def calls(self, calls: dict[str, Callable[[], object]], *, repeats: int | None = None,
              warmup: int | None = None) -> dict[str, list[float]]:
        """The wall milliseconds of each named call (CPU-side work: a metric, a readback, a
        reference), interleaved round by round (rounds()); returns {name: [ms per round]}."""
        def timed(fn):
            def run():
                t0 = time.perf_counter()
                fn()
                return {"wall": (time.perf_counter() - t0) * 1e3}
            return run

        out = self.rounds({n: timed(fn) for n, fn in calls.items()}, repeats=repeats, warmup=warmup)
        return {n: v["wall"] for n, v in out.items()}

    # -- records and tables --------------------------------------------------------------------------
    def record(self, params: dict, metric: str, unit: str, samples, **kw) -> dict:
        return self.recorder.add(params, metric, unit, samples, **kw)

    def record_all(self, params: dict, values: dict[str, list[float]], unit: str = "ms", keys=None) -> None:
        """One record per metric of a configuration's rounds (all, or `keys` where present)."""
        for k in (keys if keys is not None else values):
            if k in values:
                self.record(params, k, unit, values[k])

    def find(self, metric=None, **params) -> list[dict]:
        return self.recorder.find(metric, **params)

    def table(self, records=None, rows=(), columns: str = "metric", **kw) -> str:
        recs = self.recorder.records if records is None else records
        return _records.table(recs, list(rows), columns, **kw)

    def print_ab(self, side: str, a, b, records=None, rows=(), note: bool = True, **kw) -> None:
        """Prints records.ab_table of this run's records (or `records`): side `a` against `b`."""
        recs = self.recorder.records if records is None else list(records)
        print(_records.ab_table(recs, side, a, b, list(rows), **kw))
        if note and recs:
            print(_records.spread_note(recs, kw.get("spread", "iqr")) + f"; verdict: {b} against {a} "
                  "(records.figure_verdict)")

    def print_table(self, records=None, rows=(), columns: str = "metric", note: bool = True, **kw) -> None:
        recs = self.recorder.records if records is None else list(records)
        print(_records.table(recs, list(rows), columns, **kw))
        if note and recs:
            print(_records.spread_note(recs, kw.get("spread", "iqr")))


__all__ = ["WARMUP", "parse_value", "parse_set", "device_header", "arguments", "open_renderer", "goal_verdict",
           "Bench"]
