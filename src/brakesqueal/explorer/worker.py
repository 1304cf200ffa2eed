"""Work off the interaction path: one thread per lane, only the latest request computed.

A :class:`LatestWorker` holds at most one pending job.  Submitting while a
job runs replaces the pending one (stale requests are dropped, never
queued), so a slider dragged across a hundred values costs at most the job
running now plus one for the value where it stopped.  Results are handed to
the Bokeh document with ``add_next_tick_callback`` (the thread-safe way to
change a served document).  A running job can be cancelled: the job's
progress callback raises :class:`Cancelled` at its next call.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from functools import partial
from typing import Generic, TypeVar, cast

__all__ = ["Cancelled", "LatestWorker"]

log = logging.getLogger(__name__)

_J = TypeVar("_J")
_R = TypeVar("_R")


class Cancelled(Exception):
    """Raised inside a job whose lane was cancelled or superseded."""


class LatestWorker(Generic[_J, _R]):
    """A background lane that computes only the latest submitted job.

    Parameters
    ----------
    compute : callable
        ``compute(job, check) -> result`` run in the worker thread; ``check(fraction)``
        reports progress and raises :class:`Cancelled` when the job is cancelled.
    deliver : callable
        ``deliver(job, result, error)`` run on the document's event loop (``result`` is ``None`` when
        ``error`` is not).
    schedule : callable
        Runs a zero-argument callable on the document's event loop (``doc.add_next_tick_callback``).
    progress : callable, optional
        ``progress(fraction)`` run on the event loop (throttled by the job's own reports).
    name : str
        Thread name.
    """

    def __init__(self, compute: Callable[[_J, Callable[[float], None]], _R],
                 deliver: Callable[[_J, _R | None, BaseException | None], None],
                 schedule: Callable[[Callable[[], None]], object], *,
                 progress: Callable[[float], None] | None = None, name: str = "explorer-worker") -> None:
        self._compute = compute
        self._deliver = deliver
        self._schedule = schedule
        self._progress = progress
        self._cv = threading.Condition()
        self._pending: _J | None = None
        self._has_pending = False
        self._cancel = False
        self._stop = False
        self.busy = False
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    def submit(self, job: _J) -> None:
        """Compute ``job`` next (replaces a pending job that has not started)."""
        with self._cv:
            self._pending = job
            self._has_pending = True
            self._cv.notify()

    @property
    def superseded(self) -> bool:
        """Whether a newer job waits (the running one may stop early)."""
        return self._has_pending

    def cancel(self) -> None:
        """Cancel the running job and drop the pending one."""
        with self._cv:
            self._cancel = True
            dropped, had = self._pending, self._has_pending
            self._has_pending = False
            self._pending = None
        if had:  # a job that never started is reported as cancelled too
            self._schedule(partial(self._deliver, cast("_J", dropped), None, Cancelled("cancelled")))  # it was set

    def stop(self) -> None:
        """End the thread after the running job (the session is gone)."""
        with self._cv:
            self._stop = True
            self._cancel = True
            self._cv.notify()

    def _check(self, fraction: float) -> None:
        if self._cancel or self._stop:
            raise Cancelled("cancelled")
        if self._progress is not None:
            progress = self._progress
            self._schedule(lambda: progress(fraction))

    def _run(self) -> None:
        while True:
            with self._cv:
                while not self._has_pending and not self._stop:
                    self._cv.wait()
                if self._stop:
                    return
                job = cast("_J", self._pending)  # set with _has_pending
                self._pending, self._has_pending, self._cancel = None, False, False
                self.busy = True
            result: _R | None = None
            error: BaseException | None = None
            try:
                result = self._compute(job, self._check)
            except Cancelled as exc:
                error = exc
            except Exception as exc:  # shown in the app; the lane keeps running
                log.debug("explorer job failed", exc_info=True)
                error = exc
            finally:
                self.busy = False
            if self._stop:
                return
            self._schedule(partial(self._deliver, job, result, error))
