"""A sweep's journal: every finished configuration's row on disk the moment it finishes.

A sweep with a results folder keeps ``journal.jsonl`` there, one JSON object a line:

  {"type": "sweep", ...}   the header: the sweep's definition (the keyword arguments of
                           ssrlab.lab.run.sweep, enough to run it again), the digest of its
                           configurations, the code that runs it (ssrlab version, git revision,
                           shader digest), and when it started
  {"type": "row", "config_key": K, "row": {...}}
                           one finished configuration: its key (a digest of everything that
                           defines it: scene, view, settings, timing protocol, reference, device)
                           and its row
  {"type": "mix", ...}     a later run whose definition or code differed, told to go on anyway
                           (force_mix): the rows after it come from that run

Each line is written with a single write() of the whole line, then flushed and fsync()ed
before the sweep goes on: a crash (power loss, a killed scheduler, Ctrl-C) loses at most the
configurations still running. A last line cut short by a crash is ignored when the journal
is read again (and the configuration it held runs again). Appending only, never rewriting,
is what makes this safe without locks: one process (the sweep's client) writes the journal.

Resuming (``ssrlab bench --resume FOLDER``, or ``sweep(..., journal=FOLDER)`` again) runs only
the configurations without a row. A journal written by another sweep definition or another
version of the code refuses to take rows of this one (SweepMismatchError) unless force_mix:
mixing rows of two code versions would put two renderers' times and errors on one front.
"""

from __future__ import annotations

import datetime
import hashlib
import json
import math
import os
from pathlib import Path
from typing import Any

JOURNAL_NAME = "journal.jsonl"
FORMAT = 1


class SweepMismatchError(ValueError):
    """The journal in a results folder belongs to another sweep definition or code version."""


def config_key(task: tuple | list) -> str:
    """A digest of a configuration's task arguments (see ssrlab.lab.run.sweep): the same
    configuration always has the same key, on any machine."""
    return hashlib.sha256(json.dumps(list(task), sort_keys=True, default=str).encode()).hexdigest()[:24]


def _json_safe(v):
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def _now() -> str:
    return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")


def read(folder) -> tuple[dict | None, dict[str, dict]]:
    """The header (None without a journal) and the rows by configuration key of the journal
    in `folder`. A line that does not parse (the last one, cut short by a crash) is skipped."""
    path = Path(folder) / JOURNAL_NAME
    if not path.is_file():
        return None, {}
    header, rows = None, {}
    with open(path, "rb") as f:
        for raw in f:
            try:
                entry = json.loads(raw)
            except ValueError:
                continue
            if not isinstance(entry, dict):
                continue
            if entry.get("type") == "sweep" and header is None:
                header = entry
            elif entry.get("type") == "row" and isinstance(entry.get("row"), dict):
                rows.setdefault(entry["config_key"], entry["row"])  # the first finished row counts
    return header, rows


class Journal:
    """The journal of one sweep in `folder` (created when missing). `definition`: the sweep's
    keyword arguments (JSON); `configs`: the configuration keys in sweep order; `code`: what
    runs the sweep. An existing journal of another definition or code raises
    SweepMismatchError unless force_mix (then a "mix" line records the change)."""

    def __init__(self, folder, definition: dict, configs: list[str], code: dict, *, force_mix: bool = False):
        self.folder = Path(folder)
        self.path = self.folder / JOURNAL_NAME
        if self.folder.exists() and not self.folder.is_dir():
            raise NotADirectoryError(f"journal folder {self.folder} is a file")
        digest = hashlib.sha256(json.dumps(sorted(configs)).encode()).hexdigest()[:24]
        header, self.rows = read(self.folder)
        self.resumed = header is not None
        if self.path.is_file() and header is None and self.path.stat().st_size > 0:
            raise SweepMismatchError(f"{self.path} has no sweep header: it is not an ssrlab journal")
        entry = {"type": "sweep", "format": FORMAT, "definition": definition, "configs_digest": digest,
                 "configs": len(configs), "code": code, "started": _now()}
        self.folder.mkdir(parents=True, exist_ok=True)
        self._end_cut_line()
        if header is None:
            self._append(entry)
            self.header = entry
            return
        self.header = header
        why = []
        if header.get("configs_digest") != digest:
            old = set(self.rows)
            shared = len(old & set(configs))
            why.append(f"its configurations differ ({header.get('configs')} in the journal's sweep, {len(configs)} "
                       f"in this one; {shared} of this one's already have a row)")
        if header.get("code") != code:
            changed = ", ".join(f"{k} {header.get('code', {}).get(k)!r} -> {v!r}" for k, v in code.items()
                                if header.get("code", {}).get(k) != v)
            why.append(f"the code differs ({changed})")
        if why:
            if not force_mix:
                raise SweepMismatchError(
                    f"{self.path} holds rows of another sweep: {'; '.join(why)}. Mixing their rows would put "
                    f"results of different definitions or code on one front; use another results folder, or "
                    f"force_mix=True (--force-mix) to keep the old rows and add this sweep's")
            self._append({"type": "mix", "definition": definition, "configs_digest": digest, "code": code,
                          "reasons": why, "started": _now()})

    def _end_cut_line(self) -> None:
        """Ends a last line cut short by a crash, so the next entry starts a line of its own (the
        cut one stays unparseable and is skipped)."""
        if not self.path.is_file() or self.path.stat().st_size == 0:
            return
        with open(self.path, "rb") as f:
            f.seek(-1, os.SEEK_END)
            if f.read(1) == b"\n":
                return
        fd = os.open(self.path, os.O_WRONLY | os.O_APPEND)
        try:
            os.write(fd, b"\n")
            os.fsync(fd)
        finally:
            os.close(fd)

    def _append(self, entry: dict) -> None:
        line = (json.dumps({k: _json_safe(v) for k, v in entry.items()}, allow_nan=False, default=str)
                + "\n").encode()
        # O_APPEND: every write lands at the end, whole; fsync before the sweep goes on.
        fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
        try:
            os.write(fd, line)
            os.fsync(fd)
        finally:
            os.close(fd)

    def note(self, entry: dict) -> None:
        """Writes another entry (e.g. {"type": "reference", ...}: a reference task's result)."""
        self._append(entry)

    def add(self, key: str, row: dict[str, Any]) -> None:
        """Writes a finished configuration's row (to disk before this returns)."""
        safe = {k: _json_safe(v) for k, v in row.items()}
        self._append({"type": "row", "config_key": key, "row": safe})
        self.rows.setdefault(key, safe)


def definition_of(folder) -> dict:
    """The sweep definition (keyword arguments of ssrlab.lab.run.sweep) stored in `folder`'s
    journal: what ``ssrlab bench --resume FOLDER`` runs again."""
    header, _ = read(folder)
    if header is None:
        raise FileNotFoundError(f"no sweep journal ({JOURNAL_NAME}) in {folder}")
    return dict(header["definition"])


__all__ = ["JOURNAL_NAME", "SweepMismatchError", "Journal", "config_key", "read", "definition_of"]
