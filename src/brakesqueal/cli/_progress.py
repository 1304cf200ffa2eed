"""Progress reporting of long commands: a rich bar on a terminal, periodic one-line updates otherwise.

The numbers are honest (issue 29):

- the fraction shown never decreases (a caller's fraction that jumps back is ignored) and stays at most
  99.9 % until the work is done; "100.0 %" is shown once, when the ``with`` block ends without an error;
- no line is printed twice;
- an ETA ("about N s left") is printed only once it means something: at least :data:`ETA_MIN_FRACTION`
  done, after at least :data:`ETA_MIN_LINES` earlier lines, and when the rates of progress over the last
  two intervals between lines agree within a factor :data:`ETA_RATE_AGREEMENT`; it extrapolates the latest
  rate (a stiff start, slow at 1 % and fast after, gives no ETA rather than a wrong one).
"""

from __future__ import annotations

import contextlib
import sys
import time
from collections.abc import Callable, Iterator

__all__ = ["ETA_MIN_FRACTION", "ETA_MIN_LINES", "ETA_RATE_AGREEMENT", "LineReporter", "progress"]

#: Least fraction done before an ETA is printed.
ETA_MIN_FRACTION = 0.10
#: Least number of earlier progress lines before an ETA is printed.
ETA_MIN_LINES = 3
#: Largest ratio between the rates of the last two intervals for which an ETA is printed.
ETA_RATE_AGREEMENT = 2.0
#: Largest fraction shown before the caller says the work is done.
_NOT_DONE = 0.999


class LineReporter:
    """One progress line every ``every`` seconds, with the rules of this module (a callable taking the fraction).

    It has no ``write`` attribute on purpose: callers such as the sweep runner take an object with one for a
    text stream.

    Parameters
    ----------
    label : str
        What is being computed.
    every : float
        Seconds between lines.
    clock : callable, optional
        Monotonic clock in seconds (default :func:`time.monotonic`; tests pass a fake).
    write : callable, optional
        Receives each line without newline (default: print to stderr).
    """

    def __init__(self, label: str, every: float, *, clock: Callable[[], float] = time.monotonic,
                 write: Callable[[str], None] | None = None) -> None:
        self.label, self.every, self.clock = label, every, clock
        self._out = write if write is not None else (lambda s: print(s, file=sys.stderr, flush=True))
        self.start = self.last = clock()
        self.frac = 0.0  # the largest fraction seen, clamped below 1 until done
        self.points: list[tuple[float, float]] = []  # (time, fraction) of the printed lines
        self.last_text = ""

    def __call__(self, frac: float) -> None:
        """Record the completed fraction ``frac`` (clamped to [0, 99.9 %], never lower than before)."""
        try:
            f = float(frac)
        except (TypeError, ValueError):
            return
        if f == f:  # not NaN
            self.frac = max(self.frac, min(max(f, 0.0), _NOT_DONE))
        now = self.clock()
        if now - self.last >= self.every:
            self._emit(now, self.frac)

    def done(self) -> None:
        """The work is done: print "100.0 %" once (only when a line was printed before: quick runs stay quiet)."""
        if self.points:
            self._emit(self.clock(), 1.0)

    def eta(self, now: float, frac: float) -> float | None:
        """Seconds left, or ``None`` while an ETA would not mean anything (see the module's rules)."""
        if frac < ETA_MIN_FRACTION or frac >= 1.0 or len(self.points) < ETA_MIN_LINES:
            return None
        (t0, f0), (t1, f1) = self.points[-2:]
        r_prev = (f1 - f0) / (t1 - t0) if t1 > t0 else 0.0
        r_last = (frac - f1) / (now - t1) if now > t1 else 0.0
        if r_prev <= 0 or r_last <= 0 or max(r_prev, r_last) > ETA_RATE_AGREEMENT * min(r_prev, r_last):
            return None
        return (1.0 - frac) / r_last

    def _emit(self, now: float, frac: float) -> None:
        pct = f"{100 * frac:5.1f}%"
        if pct == self.last_text:  # nothing new to say
            self.last = now
            return
        eta = self.eta(now, frac)
        tail = f" (about {eta:.0f} s left)" if eta is not None else ""
        self._out(f"brakesqueal: {self.label}: {pct} after {now - self.start:.0f} s{tail}")
        self.last_text = pct
        self.last = now
        self.points.append((now, frac))


@contextlib.contextmanager
def progress(label: str, enabled: bool | None = None, *, every: float | None = None
             ) -> Iterator[Callable[[float], None]]:
    """Yield a callback taking the completed fraction in [0, 1].

    The fraction shown never decreases, stays below 100 % until the ``with`` block ends without an
    error (then 100 % is shown once), and an ETA is printed only when it is meaningful (at least 10 %
    done, three earlier lines, a steady rate: see :class:`LineReporter`).

    Parameters
    ----------
    label : str
        What is being computed (``"map"``).
    enabled : bool or None
        ``None``: a :mod:`rich` progress bar when stderr is a terminal, else one
        line every ``every`` seconds (so scripts and CI logs show progress too).
        ``False``: silent.  ``True``: as ``None``.
    every : float, optional
        Seconds between the one-line updates on a non-terminal (default
        ``$BRAKESQUEAL_PROGRESS_EVERY``, else 10).
    """
    if every is None:
        import os

        try:
            every = max(float(os.environ.get("BRAKESQUEAL_PROGRESS_EVERY", "10")), 0.0)
        except ValueError:
            every = 10.0
    if enabled is False:
        yield lambda frac: None
        return
    if sys.stderr.isatty():
        from rich.console import Console
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

        # on stderr: stdout carries the command's results (JSON, tables) and may be a pipe; no remaining-time
        # column: rich extrapolates from the first updates, meaningless for a stiff start
        with Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.percentage:>5.1f}%"),
                      TimeElapsedColumn(), transient=False, console=Console(file=sys.stderr)) as bar:
            task = bar.add_task(label, total=1.0)
            best = [0.0]

            def update(frac: float) -> None:
                if frac == frac:
                    best[0] = max(best[0], min(max(float(frac), 0.0), _NOT_DONE))
                bar.update(task, completed=best[0])

            yield update
            bar.update(task, completed=1.0)
        return
    rep = LineReporter(label, every)
    yield rep
    rep.done()
