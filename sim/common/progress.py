"""Progress of long work, for a person at a terminal and for a log file alike.

On a terminal a tqdm bar redraws itself in place. Written into a file (a batch job's log, ``2> log.txt``, a pipe) the
same bar is one ever longer line of carriage returns, and any other line written meanwhile lands inside it. There
`progress` gives plain lines instead, at most one per PLAIN_EVERY_S seconds (``tasks: 120/2400 runs (5 %), 3.1 min,
about 58 min left``) and one when the work is done, if it took long enough to print any; work shorter than that
prints nothing. Lines of their own (an estimate, a warning) go through the bar's `write`, which keeps them out of a
bar on a terminal.
"""
from __future__ import annotations

import sys
import time
from typing import Any, TextIO

#: seconds between two plain progress lines (stderr not a terminal)
PLAIN_EVERY_S = 30.0


def _duration(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    return f"{seconds / 60:.1f} min" if seconds < 5400 else f"{seconds / 3600:.1f} h"


class PlainProgress:
    """A progress report as plain lines on `stream`: what tqdm offers the workbench (`update`, `write`, `close`, a
    context manager, `n` and `total`), at most one line per `every` seconds."""

    def __init__(self, total: int | None, desc: str, unit: str, *, initial: int = 0, stream: TextIO | None = None,
                 every: float | None = None) -> None:
        self.total, self.desc, self.unit, self.n = total, desc, unit, initial
        self.stream = stream or sys.stderr
        self.every = PLAIN_EVERY_S if every is None else every
        self.started = self.last = time.monotonic()
        self.initial = initial
        self.lines = 0

    def update(self, n: int = 1) -> None:
        self.n += n
        now = time.monotonic()
        if now - self.last >= self.every:
            self.last = now
            self._line(now)

    def write(self, text: str, file: TextIO | None = None) -> None:
        """One line of its own (as `tqdm.write`), on `file` (default the report's stream)."""
        stream = file or self.stream
        stream.write(text.rstrip("\n") + "\n")
        stream.flush()

    def close(self) -> None:
        if self.lines:
            self._line(time.monotonic(), done=True)
            self.lines = 0

    def __enter__(self) -> "PlainProgress":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def _line(self, now: float, done: bool = False) -> None:
        elapsed = now - self.started
        count = f"{self.n}/{self.total}" if self.total else f"{self.n}"
        share = f" ({100 * self.n / self.total:.0f} %)" if self.total else ""
        text = f"{self.desc}: {count} {self.unit}{share}, {_duration(elapsed)}"
        made = self.n - self.initial
        if done:
            text += ", done"
        elif self.total and made > 0:
            text += f", about {_duration(elapsed / made * (self.total - self.n))} left"
        self.lines += 1
        self.write(text)


def progress(total: int | None, desc: str, unit: str, *, initial: int = 0, enabled: bool = True,
             stream: TextIO | None = None, leave: bool = True) -> Any:
    """The progress report of `total` steps of `unit` ("run", "pt") named `desc` on `stream` (stderr): a tqdm bar on a
    terminal, `PlainProgress` lines otherwise, nothing (a disabled bar) unless `enabled`."""
    from tqdm import tqdm

    stream = stream or sys.stderr
    terminal = hasattr(stream, "isatty") and stream.isatty()
    if enabled and not terminal:
        return PlainProgress(total, desc, unit, initial=initial, stream=stream)
    return tqdm(total=total, initial=initial, desc=desc, unit=unit, disable=not enabled, file=stream,
                dynamic_ncols=True, leave=leave)
