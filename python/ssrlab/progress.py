"""Progress that suits where it is written.

A terminal gets tqdm's bar (redrawn in place with carriage returns), Jupyter its widget. Any
other stream (a log file, a pipe, a batch job's output) gets whole lines instead, one per step,
each ending in a newline: a bar redrawn with carriage returns turns into runs of half-drawn
bars in a log (``ssrlab render: 0/5 ssrlab render: 0/5 , opening...``).
"""

from __future__ import annotations

import sys
import time


def _in_jupyter() -> bool:
    shell = sys.modules.get("IPython")
    if shell is None:
        return False
    try:
        ip = shell.get_ipython()  # type: ignore[attr-defined]
    except Exception:
        return False
    return ip is not None and "IPKernelApp" in getattr(ip, "config", {})


def interactive(stream) -> bool:
    """True where a redrawn bar can be shown: a terminal, or a Jupyter kernel."""
    try:
        if stream.isatty():
            return True
    except (AttributeError, ValueError):
        pass
    return _in_jupyter()


class LineProgress:
    """tqdm's interface as much as ssrlab uses (update, set_postfix_str, n, total, close, with):
    one line per step, "desc: n/total unit postfix (elapsed s)"."""

    def __init__(self, total: int, desc: str = "", unit: str = "it", file=None, initial: int = 0, **_):
        self.total, self.desc, self.unit, self.n = total, desc, unit, initial
        self.file = file if file is not None else sys.stderr
        self.postfix = ""
        self._start = time.monotonic()
        self._closed = False
        self._line()

    def _line(self) -> None:
        what = f", {self.postfix}" if self.postfix else ""
        print(f"{self.desc}: {self.n}/{self.total} {self.unit}{what} ({time.monotonic() - self._start:.1f} s)",
              file=self.file, flush=True)

    def update(self, n: int = 1) -> None:
        self.n += n
        self._line()

    def set_postfix_str(self, s: str = "", refresh: bool = True) -> None:
        # A new description of the step under way: shown with the next count, not a line of its own.
        self.postfix = s

    def close(self) -> None:
        self._closed = True

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def progress_bar(total: int, desc: str, unit: str, file=None, **kwargs):
    """tqdm (a bar on a terminal, a widget in Jupyter) or, on any other stream, LineProgress."""
    file = file if file is not None else sys.stderr
    if interactive(file):
        from tqdm.auto import tqdm

        return tqdm(total=total, desc=desc, unit=unit, file=file, **kwargs)
    kwargs.pop("bar_format", None)
    return LineProgress(total, desc=desc, unit=unit, file=file, **kwargs)


def progress_callback(progress, label: str):
    """(callback, close) for a native loop's progress(done, total): `progress` None or False gives
    no callback, a callable is used as it is, True a bar: tqdm on a terminal, else a line on
    stderr every 10% (logs of batch jobs stay readable)."""
    if progress is None or progress is False:
        return None, lambda: None
    if callable(progress) and not isinstance(progress, bool):
        return progress, lambda: None

    state = {"bar": None, "shown": -1}
    tty = hasattr(sys.stderr, "isatty") and sys.stderr.isatty()

    def callback(done: int, total: int):
        if tty:
            if state["bar"] is None:
                try:
                    from tqdm import tqdm
                except ImportError:
                    state["bar"] = False
                else:
                    state["bar"] = tqdm(total=total, desc=label, unit="round")
            if state["bar"]:
                state["bar"].update(done - state["bar"].n)
                return True
        tenth = done * 10 // total
        if tenth != state["shown"]:
            state["shown"] = tenth
            print(f"{label}: {done}/{total} sample rounds", file=sys.stderr, flush=True)
        return True

    def close():
        if state["bar"]:
            state["bar"].close()

    return callback, close


__all__ = ["progress_bar", "progress_callback", "LineProgress", "interactive"]
