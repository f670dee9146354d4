"""Progress of a command's work on stderr, with its total and an estimate of the time left.

Every command whose work can pass a few seconds reports through one :class:`Progress`: on a
terminal, one line redrawn in place (a bar, the count against its total, the time so far and
the time left); without one (stderr not a tty: a pipe, a log, a CI job), a plain line every
few seconds, so a long run is never silent. The library's ``progress`` callables report
``(done, total)`` or a fraction; this is where they are said (the library never prints).
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import IO

#: seconds before the first report (a run shorter than this says nothing)
FIRST_AFTER = 1.0
#: seconds between the lines written without a terminal
EVERY = 3.0
#: characters of the bar drawn on a terminal
BAR_WIDTH = 25


class Progress:
    """A run's progress on stderr: ``update(done, total)`` (or ``progress(fraction)``).

    Parameters
    ----------
    label : str
        What runs (``simulate``, ``sweep``, ``frontier --recommend``), the line's start.
    unit : str, optional
        What is counted (``points``, ``probes``); empty for a fraction of the work.
    stream : file, optional
        Where the lines go (default ``sys.stderr``).
    tty : bool, optional
        Redraw one line in place (default: whether ``stream`` is a terminal).
    """

    def __init__(
        self, label: str, unit: str = "", stream: IO[str] | None = None, tty: bool | None = None
    ) -> None:
        self.label = label
        self.unit = unit
        self.stream = sys.stderr if stream is None else stream
        isatty = getattr(self.stream, "isatty", None)
        self.tty = bool(isatty()) if tty is None and isatty is not None else bool(tty)
        self.t0 = time.perf_counter()
        self.t_work: float | None = None
        self.done = 0.0
        self.total = 1.0 if not unit else 0.0
        self.extra = ""
        self.drawn = False
        self.last_line = -1.0
        self.last_text = ""
        self.lock = threading.Lock()
        self.stop = threading.Event()
        # a heartbeat: the line is said every few seconds even while one unit of work runs
        self.thread = threading.Thread(target=self._beat, daemon=True)
        self.thread.start()

    # ---------------------------------------------------------------- what the work reports
    def __call__(self, fraction: float) -> None:
        """A fraction of the work done (0 to 1), as the integrator reports it."""
        self.update(fraction, 1.0)

    def update(self, done: float, total: float, extra: str = "") -> None:
        """``done`` of ``total`` units finished; ``extra`` is said after the count."""
        with self.lock:
            finished = self.done >= self.total
            if self.t_work is None:  # the estimate counts from the work's first report
                self.t_work = time.perf_counter()
            self.done, self.total = float(done), float(total)
            if extra:
                self.extra = extra
        self._say(force=done >= total and not finished)

    def say(self, message: str) -> None:
        """A message line; on a terminal the progress line is drawn again below it."""
        with self.lock:
            if self.tty and self.drawn:
                print(f"\r{message:<{len(self.last_text)}}", file=self.stream, flush=True)
                self.last_text = ""
                self.drawn = False
            else:
                print(message, file=self.stream, flush=True)
        if self.tty and self.t_work is not None:
            self._say(force=True)

    def close(self) -> None:
        """Stop the heartbeat and end the terminal's line."""
        self.stop.set()
        self.thread.join(timeout=1.0)
        with self.lock:
            if self.drawn and self.tty:
                print(file=self.stream, flush=True)
            self.drawn = False

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ---------------------------------------------------------------- what is said
    def text(self) -> str:
        """The line: the count against its total, the time so far and the time left."""
        elapsed = time.perf_counter() - self.t0
        frac = min(max(self.done / self.total, 0.0), 1.0) if self.total > 0 else 0.0
        if self.t_work is None or self.total <= 0:
            count, frac = "preparing", 0.0
        elif self.unit:
            count = f"{int(self.done)}/{int(self.total)} {self.unit}"
        else:
            count = f"{int(100 * frac):3d}%"
        if self.tty and self.total > 0:
            filled = int(BAR_WIDTH * frac)
            count = f"[{'#' * filled}{'-' * (BAR_WIDTH - filled)}] {count}"
        if frac >= 1.0:
            left = "done"
        elif frac > 0.0 and self.t_work is not None:
            working = time.perf_counter() - self.t_work
            left = f"about {duration_text(working * (1.0 - frac) / frac)} left"
        else:
            left = "time left not known yet"
        extra = f" ({self.extra})" if self.extra else ""
        return f"{self.label}: {count}{extra}, {duration_text(elapsed)} so far, {left}"

    def _say(self, force: bool = False) -> None:
        with self.lock:
            now = time.perf_counter()
            if now - self.t0 < FIRST_AFTER and not (force and self.drawn):
                return
            if not self.tty and not force and now - self.last_line < EVERY:
                return
            line = self.text()
            if self.tty:
                if line == self.last_text:
                    return
                print(f"\r{line:<{len(self.last_text)}}", end="", file=self.stream, flush=True)
            else:
                print(line, file=self.stream, flush=True)
            self.last_text = line
            self.last_line = now
            self.drawn = True

    def _beat(self) -> None:
        while not self.stop.wait(EVERY if not self.tty else 1.0):
            if self.total > 0 and self.done >= self.total:
                continue  # said once when it ended
            try:
                self._say()
            except (OSError, ValueError):  # the stream was closed under it: stop saying
                return


@contextmanager
def progress_bar(label: str, unit: str = "", quiet: bool = False) -> Iterator[Progress | None]:
    """A command's :class:`Progress` (None with ``--quiet``: nothing said), closed on every
    path out of the block (its heartbeat is a thread)."""
    bar = None if quiet else Progress(label, unit=unit)
    try:
        yield bar
    finally:
        if bar is not None:
            bar.close()


def duration_text(seconds: float) -> str:
    """A duration a reader takes in at a glance: ``12 s``, ``3 min 5 s``, ``2 h 10 min``."""
    s = max(0.0, float(seconds))
    if s < 60.0:
        return f"{s:.0f} s" if s >= 10.0 else f"{s:.1f} s"
    if s < 3600.0:
        return f"{int(s // 60)} min {int(s % 60)} s"
    return f"{int(s // 3600)} h {int(s % 3600 // 60)} min"


class Stages:
    """A run counted in stages (``k/N stages``): each message said starts the next stage.

    ``stages(message)`` says the message (``label: message``) and counts the stages before it
    as done, against ``total`` (raised when a route says more); :meth:`end` counts all done.
    With ``bar`` None (``--quiet``) nothing is said.
    """

    def __init__(self, bar: Progress | None, total: int) -> None:
        self.bar = bar
        self.total = total
        self.started = 0

    def __call__(self, message: str) -> None:
        if self.bar is None:
            return
        self.bar.say(f"{self.bar.label}: {message}")
        self.started += 1
        self.total = max(self.total, self.started)
        self.bar.update(self.started - 1, self.total)

    def end(self) -> None:
        if self.bar is not None:
            self.bar.update(self.total, self.total)
