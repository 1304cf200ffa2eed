"""Progress reporting of long commands: a rich bar on a terminal, periodic one-line updates otherwise."""

from __future__ import annotations

import contextlib
import sys
import time
from collections.abc import Callable, Iterator

__all__ = ["progress"]


@contextlib.contextmanager
def progress(label: str, enabled: bool | None = None, *, every: float | None = None
             ) -> Iterator[Callable[[float], None]]:
    """Yield a callback taking the completed fraction in [0, 1].

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
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

        # on stderr: stdout carries the command's results (JSON, tables) and may be a pipe
        with Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.percentage:>5.1f}%"),
                      TimeElapsedColumn(), TimeRemainingColumn(), transient=False,
                      console=Console(file=sys.stderr)) as bar:
            task = bar.add_task(label, total=1.0)
            yield lambda frac: bar.update(task, completed=min(max(frac, 0.0), 1.0))
        return
    start = last = time.monotonic()

    def line(frac: float) -> None:
        nonlocal last
        now = time.monotonic()
        if now - last >= every or frac >= 1.0 and now - start >= every:
            eta = (now - start) * (1 - frac) / frac if frac > 0 else float("nan")
            print(f"brakesqueal: {label}: {100 * frac:5.1f}% after {now - start:.0f} s (about {eta:.0f} s left)",
                  file=sys.stderr, flush=True)
            last = now

    yield line
