"""Work off the interaction path: one thread per lane, only the latest request computed.

A :class:`LatestWorker` holds at most one pending job.  Submitting while a
job runs replaces the pending one (stale requests are dropped, never
queued), so a slider dragged across a hundred values costs at most the job
running now plus one for the value where it stopped.  Results are handed to
the Bokeh document with ``add_next_tick_callback`` (the thread-safe way to
change a served document).  A running job can be cancelled: the job's
progress callback raises :class:`Cancelled` at its next call.

Long computations (the simulation, the limit cycles) may not call their
progress callback for a long time (setting up, compiling, a stiff stretch).
They run in a child process (:class:`ChildProcess`) that the lane's thread
watches: a cancel kills it, so the computation stops within
:data:`POLL_S` plus the time to kill a process, whatever it is doing.
"""

from __future__ import annotations

import copyreg
import io
import logging
import multiprocessing
import os
import pickle
import signal
import threading
import time
import types
from collections.abc import Callable
from functools import partial
from typing import Any, Generic, TypeVar, cast

from ..errors import BrakesquealError

__all__ = ["Cancelled", "LatestWorker", "ChildProcess", "ComputationProcessError", "CannotSend", "POLL_S"]

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

    @property
    def cancelled(self) -> bool:
        """Whether the running job was cancelled (or the lane stopped): it should stop now."""
        return self._cancel or self._stop

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


#: Seconds between two looks of a lane's thread at its cancel flag while a child process computes.
POLL_S = 0.05
#: Seconds between two progress reports a child process sends (more frequent ones are dropped).
_PROGRESS_S = 0.05


class ComputationProcessError(BrakesquealError):
    """A child process of the explorer failed without a picklable error, or ended unexpectedly."""


class CannotSend(Exception):
    """A call's function or arguments cannot be pickled for a child process (nothing was started)."""


def _mappingproxy(mapping: dict[Any, Any]) -> types.MappingProxyType[Any, Any]:
    return types.MappingProxyType(mapping)


def _dumps(obj: object) -> bytes:
    """Pickle ``obj`` for a child process (read-only mappings, which parameter spaces hold, included)."""
    buf = io.BytesIO()
    pickler = pickle.Pickler(buf, protocol=pickle.HIGHEST_PROTOCOL)
    table = dict(copyreg.dispatch_table)
    table[types.MappingProxyType] = lambda m: (_mappingproxy, (dict(m),))
    pickler.dispatch_table = table
    pickler.dump(obj)
    return buf.getvalue()


def _portable(exc: BaseException) -> BaseException:
    """``exc`` if it survives pickling, else a :class:`ComputationProcessError` with its message."""
    try:
        back = pickle.loads(_dumps(exc))
        if isinstance(back, BaseException) and str(back) == str(exc):
            return back
    except Exception:  # an error object that cannot cross: its text does
        pass
    text = str(exc) if isinstance(exc, BrakesquealError) else f"{type(exc).__name__}: {exc}"
    return ComputationProcessError(text)


def _child_main(conn: Any, parent: int) -> None:
    """The child process: run each call received on ``conn``, send its progress and its result or error."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C in the terminal is the server's to handle
    while True:
        try:
            fn, args = pickle.loads(conn.recv_bytes())
        except (EOFError, OSError):
            return  # the server is gone
        last = [0.0]

        def progress(fraction: float) -> None:
            if os.getppid() != parent:
                os._exit(0)  # the server died: compute no further
            now = time.monotonic()
            if now - last[0] >= _PROGRESS_S or fraction >= 1.0:
                last[0] = now
                conn.send(("progress", float(fraction)))

        try:
            reply = ("result", fn(*args, progress=progress))
        except BaseException as exc:  # sent to the lane, which shows it
            reply = ("error", _portable(exc))
        try:
            conn.send_bytes(_dumps(reply))
        except (EOFError, OSError):
            return
        except Exception as exc:  # a result that cannot be pickled
            conn.send_bytes(_dumps(("error", _portable(exc))))


class ChildProcess:
    """A Python process that runs one call at a time for a lane, and is killed when the lane cancels it.

    Started on the first :meth:`call` and kept for the next ones (its imports and compiled code stay
    loaded); a cancel kills it and the next call starts a new one.  Started with ``spawn`` (never
    ``fork``: the server has threads).

    Parameters
    ----------
    name : str
        Process name.
    """

    def __init__(self, name: str = "explorer-child") -> None:
        self.name = name
        self._proc: Any = None
        self._conn: Any = None
        self._lock = threading.Lock()

    @property
    def alive(self) -> bool:
        """Whether the child process runs."""
        return self._proc is not None and self._proc.is_alive()

    @property
    def pid(self) -> int | None:
        """The child's process id (None before the first call and after a kill)."""
        return None if self._proc is None else int(self._proc.pid)

    def _start(self) -> Any:
        ctx = multiprocessing.get_context("spawn")
        ours, theirs = ctx.Pipe()
        proc = ctx.Process(target=_child_main, args=(theirs, os.getpid()), name=self.name, daemon=True)
        proc.start()
        theirs.close()
        self._proc, self._conn = proc, ours
        return ours

    def call(self, fn: Callable[..., _R], args: tuple[Any, ...], *, progress: Callable[[float], None],
             cancelled: Callable[[], bool]) -> _R:
        """``fn(*args, progress=...)`` in the child process; returns its result or raises its error.

        Parameters
        ----------
        fn : callable
            A module-level function (pickled by reference) with a keyword argument ``progress``.
        args : tuple
            Its positional arguments (pickled).
        progress : callable
            Called in this thread with each fraction the child reports (may raise :class:`Cancelled`).
        cancelled : callable
            Looked at every :data:`POLL_S`; when it returns True the child is killed and
            :class:`Cancelled` raised.

        Raises
        ------
        Cancelled
            When cancelled (the child is killed).
        CannotSend
            When ``fn`` or ``args`` cannot be pickled (nothing was started or sent).
        ComputationProcessError
            When the child ended unexpectedly.
        """
        try:  # before starting anything
            payload = _dumps((fn, args))
        except Exception as exc:  # pickle raises PicklingError, TypeError, AttributeError, ...
            raise CannotSend(f"{type(exc).__name__}: {exc}") from exc
        with self._lock:
            conn = self._conn if self.alive else self._start()
        try:
            conn.send_bytes(payload)
            while True:
                if cancelled():
                    raise Cancelled("cancelled")
                if not conn.poll(POLL_S):
                    if not self.alive:
                        code = None if self._proc is None else self._proc.exitcode
                        raise ComputationProcessError(
                            f"the computation's process ended unexpectedly (exit code {code})")
                    continue
                kind, value = pickle.loads(conn.recv_bytes())
                if kind == "progress":
                    progress(value)
                elif kind == "error":
                    raise value
                else:
                    return cast("_R", value)
        except Cancelled:
            self.kill()
            raise
        except (EOFError, OSError):
            self.kill()
            raise ComputationProcessError("the computation's process ended unexpectedly") from None

    def kill(self) -> None:
        """Kill the child process now (a running call raises :class:`Cancelled` or ends)."""
        with self._lock:
            proc, conn = self._proc, self._conn
            self._proc = self._conn = None
        if proc is not None:
            proc.kill()
            proc.join(5)
        if conn is not None:
            conn.close()

    def stop(self) -> None:
        """End the child process (the session is gone)."""
        self.kill()
