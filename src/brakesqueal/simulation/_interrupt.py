"""Ctrl-C during a simulation: never lost, never inside compiled code (issue 11).

Python delivers ``SIGINT`` as a ``KeyboardInterrupt`` at the next bytecode the
interpreter runs.  Two places where that bytecode is not ours made
``brakesqueal simulate`` misbehave:

* numba-compiled code that *returns an array* calls back into the
  interpreter while boxing it (``numba.core.serialize._numba_unpickle``); a
  pending interrupt is raised there, numba does not check for it, and the
  process continued with a ``SystemError`` or crashed with a segmentation
  fault when the integrator returned (the kernels now return scalars only
  and run in calls of about 0.1 s);
* ctypes callbacks of llvmlite during a numba compilation swallow the
  exception (it goes to :func:`sys.unraisablehook`: "Exception ignored on
  calling ctypes callback function"), so an interrupt during a cold compile
  was lost and the run went on.

:func:`interrupt_guard` installs (in the main thread, when the default
handler is active) a handler that records the interrupt *and* raises it, and
an unraisable hook that keeps such swallowed interrupts quiet and delivers
them again (so they are raised as soon as the interpreter runs its own code);
the simulation also calls :func:`check_interrupt` at safe points.  While
numba compiles (this thread holds its compiler lock) the interrupt is only
recorded: unwinding through llvmlite could abort the process on an LLVM
assertion, so it is raised at the next safe point after the compilation.
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from collections.abc import Iterator
from typing import Any

__all__ = ["interrupt_guard", "check_interrupt"]

_state = {"depth": 0, "flag": False, "redeliver": 0}


def _compiling() -> bool:
    """Whether this thread holds numba's compiler lock (an LLVM compilation must not be unwound)."""
    mod = sys.modules.get("numba.core.compiler_lock")
    lock = getattr(getattr(mod, "global_compiler_lock", None), "_lock", None)
    try:
        return bool(lock._is_owned())  # type: ignore[union-attr]
    except AttributeError:
        return False


def _handler(signum: int, frame: Any) -> None:
    _state["flag"] = True
    if _compiling():
        # raised at the next safe point (check_interrupt) once the compilation has finished: unwinding
        # through llvmlite's callbacks could abort the process (an LLVM assertion)
        return
    raise KeyboardInterrupt


def _unraisable(hook: Any) -> Any:
    def quiet(unraisable: Any) -> None:
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
def interrupt_guard() -> Iterator[None]:
    """Context in which a Ctrl-C is recorded as well as raised (see the module docstring).

    Nested guards share one record; the handler is installed by the outermost
    guard only, only in the main thread, and only when Python's default
    handler is active (a handler installed by the caller is left alone).
    """
    installed = hook = None
    if _state["depth"] == 0:
        _state["flag"] = False
        _state["redeliver"] = 0
        if threading.current_thread() is threading.main_thread() \
                and signal.getsignal(signal.SIGINT) is signal.default_int_handler:  # fmt: skip
            installed = signal.signal(signal.SIGINT, _handler)
            hook = sys.unraisablehook
            sys.unraisablehook = _unraisable(hook)
    _state["depth"] += 1
    try:
        yield
        check_interrupt()
    finally:
        _state["depth"] -= 1
        if _state["depth"] == 0:
            if installed is not None:
                signal.signal(signal.SIGINT, installed)
                sys.unraisablehook = hook
            _state["flag"] = False
