"""Ctrl-C: never lost, never raised inside compiled code, and a command stops within a second (issue 11).

Python delivers ``SIGINT`` as a ``KeyboardInterrupt`` at the next bytecode the
interpreter runs.  Three places where that bytecode is not ours made commands
misbehave:

* numba-compiled code that *returns an array* calls back into the
  interpreter while boxing it (``numba.core.serialize._numba_unpickle``); a
  pending interrupt is raised there, numba does not check for it, and the
  process continued with a ``SystemError`` or crashed with a segmentation
  fault when the integrator returned (the kernels now return scalars only
  and run in calls of about 0.1 s);
* ctypes callbacks of llvmlite during a numba compilation swallow the
  exception (it goes to :func:`sys.unraisablehook`: "Exception ignored on
  calling ctypes callback function"), so an interrupt during a cold compile
  was lost and the run went on;
* a compilation cannot be unwound safely (an interrupt unwound through
  llvmlite's callbacks could abort the process on an LLVM assertion) and
  takes up to several seconds.

:func:`interrupt_guard` installs (in the main thread, when the default
handler is active) a handler that records the interrupt *and* raises it, and
an unraisable hook that keeps such swallowed interrupts quiet and delivers
them again (so they are raised as soon as the interpreter runs its own code);
long computations call :func:`check_interrupt` at safe points.  While numba
compiles (this thread holds its compiler lock) the interrupt is only
recorded and raised at the next safe point after the compilation.

A command-line program passes ``exit_after`` (seconds): when the interrupt
has not ended the guarded block that long after Ctrl-C (a compilation, a long
call into C), a watchdog thread — woken by :func:`signal.set_wakeup_fd`
even while the main thread runs native code — ends the process with
:func:`os._exit` and status 130.  That is safe because nothing is unwound:
outputs are written to temporary files that are registered with
:func:`remove_on_exit` (removed first), renames of finished files run in
:func:`critical` sections (the exit waits for them), and caches are written
atomically.  A second Ctrl-C while the first is pending exits at once (still
waiting for a critical section).  Library callers (no ``exit_after``) never
have their process ended.

``SIGTERM`` and ``SIGHUP`` (a ``kill``, a closed terminal) take the same path
as Ctrl-C inside a guard (:data:`TERMINATION_SIGNALS`): the interrupt is
raised and unwinds (temporary files removed), or the watchdog ends the
process; the exit status is then 128 + the signal's number (143, 129).
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from types import FrameType
from typing import Any

_Hook = Callable[["sys.UnraisableHookArgs"], object]

__all__ = ["interrupt_guard", "check_interrupt", "critical", "remove_on_exit", "exit_now", "EXIT_STATUS",
           "EXIT_AFTER_S", "TERMINATION_SIGNALS"]

#: Exit status of an interrupted command (128 + SIGINT).
EXIT_STATUS = 130
#: Seconds a command-line run waits for the interrupted code to unwind before it ends the process.
EXIT_AFTER_S = 0.5

#: Signals handled like Ctrl-C inside :func:`interrupt_guard` (exit status 128 + the signal's number).
TERMINATION_SIGNALS: tuple[int, ...] = tuple(getattr(signal, n) for n in ("SIGTERM", "SIGHUP") if hasattr(signal, n))

_state: dict[str, Any] = {"depth": 0, "flag": False, "redeliver": 0, "signum": None}
_exit_lock = threading.Lock()
_exit: dict[str, Any] = {"critical": 0, "exiting": False, "paths": {}, "signals": 0, "first": None,
                         "armed": False}


def _compiling() -> bool:
    """Whether this thread holds numba's compiler lock (an LLVM compilation must not be unwound)."""
    mod = sys.modules.get("numba.core.compiler_lock")
    lock = getattr(getattr(mod, "global_compiler_lock", None), "_lock", None)
    if lock is None:
        return False
    try:
        return bool(lock._is_owned())
    except AttributeError:
        return False


def _handler(signum: int, frame: FrameType | None) -> None:
    _state["flag"] = True
    if _compiling():
        # raised at the next safe point (check_interrupt) once the compilation has finished: unwinding
        # through llvmlite's callbacks could abort the process (an LLVM assertion); a CLI's watchdog ends the
        # process if the compilation outlasts exit_after
        return
    raise KeyboardInterrupt


def _terminate(signum: int, frame: FrameType | None) -> None:
    """SIGTERM / SIGHUP: recorded for the exit status, then handled exactly as Ctrl-C."""
    _state["signum"] = signum
    _handler(signum, frame)


def _install_termination() -> dict[int, Any]:
    """Handle :data:`TERMINATION_SIGNALS` like Ctrl-C (main thread; only where the default action is active)."""
    old: dict[int, Any] = {}
    for sig in TERMINATION_SIGNALS:
        if signal.getsignal(sig) is signal.SIG_DFL:
            old[sig] = signal.signal(sig, _terminate)
    return old


def _status() -> int:
    """Exit status of an interrupted command: 130 for Ctrl-C, 128 + the signal's number for SIGTERM/SIGHUP."""
    signum = _state["signum"]
    return EXIT_STATUS if signum is None else 128 + int(signum)


def _unraisable(hook: _Hook) -> _Hook:
    def quiet(unraisable: sys.UnraisableHookArgs) -> None:
        if isinstance(unraisable.exc_value, KeyboardInterrupt):
            # swallowed by a callback: recorded, and delivered again so that it is raised as soon as the
            # interpreter runs code of its own (a bounded number of times; check_interrupt catches the rest)
            _state["flag"] = True
            _state["redeliver"] += 1
            if _state["redeliver"] <= 100 and not _compiling():
                import _thread

                _thread.interrupt_main()
            return
        hook(unraisable)

    return quiet


def check_interrupt() -> None:
    """Raise ``KeyboardInterrupt`` if Ctrl-C was pressed inside the current :func:`interrupt_guard`."""
    if _state["flag"]:
        raise KeyboardInterrupt


@contextlib.contextmanager
def critical() -> Iterator[None]:
    """A section the exit after an unanswered Ctrl-C waits for (e.g. renaming finished files into place).

    Keep it short: it delays that exit.  Outside a CLI guard with
    ``exit_after`` it costs one lock acquisition.
    """
    with _exit_lock:
        _exit["critical"] += 1
    try:
        yield
    finally:
        with _exit_lock:
            _exit["critical"] -= 1


@contextlib.contextmanager
def remove_on_exit(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Register a temporary file (or directory) to be removed if the process is ended after a Ctrl-C.

    Parameters
    ----------
    path : str or path-like
        The temporary file; the registration ends with the context.

    Yields
    ------
    pathlib.Path
        The path.
    """
    p = Path(os.fspath(path))
    key = object()
    with _exit_lock:
        _exit["paths"][key] = p
    try:
        yield p
    finally:
        with _exit_lock:
            _exit["paths"].pop(key, None)


def _remove(p: Path) -> None:
    import shutil

    with contextlib.suppress(OSError):
        if p.is_dir() and not p.is_symlink():
            shutil.rmtree(p, ignore_errors=True)
        else:
            p.unlink()


def _try_exit() -> bool:
    """End the process (status 130) unless a critical section runs; ``False`` if it must wait."""
    with _exit_lock:
        if _exit["critical"] > 0:
            return False
        _exit["exiting"] = True
        for p in list(_exit["paths"].values()):
            _remove(p)
        # never flush Python's buffered streams here: the main thread may hold their locks
        with contextlib.suppress(OSError):
            # on a terminal: end a progress bar's line and show the cursor it hid
            os.write(2, (b"\n\x1b[?25h" if os.isatty(2) else b"") + b"brakesqueal: interrupted\n")
        os._exit(_status())
    return False  # pragma: no cover - os._exit does not return


def _watchdog(rfd: int, exit_after: float, stop: threading.Event) -> None:
    """Wake on every signal written to ``rfd``; end the process when an interrupt stays pending."""
    import select

    while not stop.is_set():
        first = _exit["first"]
        timeout = 0.05 if first is None else max(0.0, min(0.02, first + exit_after - time.monotonic()))
        try:
            ready, _, _ = select.select([rfd], [], [], timeout)
        except (OSError, ValueError):
            return
        if stop.is_set():
            return
        if ready:
            try:
                data = os.read(rfd, 64)
            except OSError:
                return
            n = data.count(bytes([signal.SIGINT]))
            for sig in TERMINATION_SIGNALS:  # handled as Ctrl-C (even while the main thread runs native code)
                if data.count(bytes([sig])):
                    n += data.count(bytes([sig]))
                    _state["signum"] = sig
            if n:
                _exit["signals"] += n
                if _exit["first"] is None:
                    _exit["first"] = time.monotonic()
        first = _exit["first"]
        if first is not None and (_exit["signals"] > 1 or time.monotonic() >= first + exit_after):
            if _try_exit():  # pragma: no cover - os._exit
                return


def exit_now(status: int = EXIT_STATUS) -> None:
    """End a command-line program at once (after Ctrl-C): flush stdout and stderr, skip the interpreter's teardown.

    Tearing down numba, LLVM and SymPy objects takes up to a second or two;
    after an interrupt nothing is left to do (outputs are complete or
    removed, caches are written atomically).  Waits for :func:`critical`
    sections and removes files registered with :func:`remove_on_exit`.
    Call it from the main thread only, and only in a program's entry point.

    Parameters
    ----------
    status : int, optional
        The exit status (default 130).
    """
    if status == EXIT_STATUS:
        status = _status()  # 128 + SIGTERM / SIGHUP when the interrupt was one of those
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    while True:
        with _exit_lock:
            if _exit["critical"] == 0:
                for p in list(_exit["paths"].values()):
                    _remove(p)
                os._exit(status)
        time.sleep(0.005)  # pragma: no cover - a critical section of another thread


@contextlib.contextmanager
def interrupt_guard(*, exit_after: float | None = None) -> Iterator[None]:
    """Context in which a Ctrl-C is recorded as well as raised (see the module docstring).

    Parameters
    ----------
    exit_after : float, optional
        Only for command-line programs: seconds after Ctrl-C after which the
        process is ended with status 130 if the interrupt has not left the
        guarded block by then (a second Ctrl-C: at once).  Files registered
        with :func:`remove_on_exit` are removed first; :func:`critical`
        sections are waited for.  Default ``None``: never.

    Notes
    -----
    Nested guards share one record; the handler (and the watchdog) is
    installed by the outermost guard only, only in the main thread, and only
    when Python's default handler is active (a handler installed by the
    caller is left alone).
    """
    installed = None
    terminations: dict[int, Any] = {}
    hook: _Hook | None = None
    watchdog: tuple[threading.Thread, threading.Event, int, int, int] | None = None
    if _state["depth"] == 0:
        _state["flag"] = False
        _state["redeliver"] = 0
        _state["signum"] = None
        if threading.current_thread() is threading.main_thread() \
                and signal.getsignal(signal.SIGINT) is signal.default_int_handler:  # fmt: skip
            installed = signal.signal(signal.SIGINT, _handler)
            terminations = _install_termination()
            hook = sys.unraisablehook
            sys.unraisablehook = _unraisable(hook)
            if exit_after is not None:
                watchdog = _start_watchdog(exit_after)
    _state["depth"] += 1
    try:
        yield
        check_interrupt()
    finally:
        _state["depth"] -= 1
        if _state["depth"] == 0:
            if watchdog is not None:
                _stop_watchdog(*watchdog)
            if installed is not None and hook is not None:  # set together
                signal.signal(signal.SIGINT, installed)
                for sig, previous in terminations.items():
                    signal.signal(sig, previous)
                sys.unraisablehook = hook
            _state["flag"] = False


def _start_watchdog(exit_after: float) -> tuple[threading.Thread, threading.Event, int, int, int] | None:
    rfd, wfd = os.pipe()
    os.set_blocking(wfd, False)
    try:
        old = signal.set_wakeup_fd(wfd, warn_on_full_buffer=False)
    except ValueError:  # pragma: no cover - not the main thread
        os.close(rfd)
        os.close(wfd)
        return None
    _exit.update(signals=0, first=None, armed=True)
    stop = threading.Event()
    t = threading.Thread(target=_watchdog, args=(rfd, exit_after, stop), name="brakesqueal-interrupt",
                         daemon=True)
    t.start()
    return t, stop, rfd, wfd, old


def _stop_watchdog(t: threading.Thread, stop: threading.Event, rfd: int, wfd: int, old: int) -> None:
    stop.set()
    signal.set_wakeup_fd(old)
    with contextlib.suppress(OSError):
        os.write(wfd, b"\0")  # wakes the watchdog at once
    t.join(1.0)
    _exit.update(signals=0, first=None, armed=False)
    for fd in (rfd, wfd):
        with contextlib.suppress(OSError):
            os.close(fd)
