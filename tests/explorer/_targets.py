"""Functions the cancel tests run in the explorer's child processes (module-level: pickled by reference)."""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from typing import Any

from brakesqueal.errors import ParameterError

#: Seconds a stubborn computation runs without a progress report (far beyond any test's patience).
STUBBORN_S = 600.0


def twice(x: float, *, progress: Callable[[float], None]) -> float:
    """Report progress and return ``2 x``."""
    progress(0.5)
    progress(1.0)
    return 2 * x


def refuse(name: str, *, progress: Callable[[float], None]) -> None:
    """Raise the one-line ParameterError a bad value gives."""
    raise ParameterError(f"The parameter '{name}' must be in [0, inf); got -1", parameter=name)


def type_error(*, progress: Callable[[float], None]) -> None:
    """Fail as a bug would (not a BrakesquealError)."""
    raise TypeError("unsupported operand")


def pid(*, progress: Callable[[float], None]) -> int:
    """The process id of the process that runs it."""
    return os.getpid()


def stubborn(seconds: float = STUBBORN_S, *, progress: Callable[[float], None]) -> str:
    """Report once, then compute for ``seconds`` without ever calling ``progress`` again (a stiff stretch, a
    compilation, a set-up: nothing a cooperative cancel can stop)."""
    progress(0.5)
    time.sleep(seconds)
    return "finished"


def stubborn_simulation(space: Any, t_end: float, *, progress: Callable[[float], None] | None = None) -> Any:
    """The explorer's simulation replaced by :func:`stubborn` (the explorer calls it with ``progress``)."""
    assert progress is not None
    return stubborn(progress=progress)
