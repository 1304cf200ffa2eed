"""The interval kernels of :mod:`._compiled` run as plain Python for a few points (no numba import).

A single verdict (``brakesqueal linearize``, ``eigen``) needs one interval
quartic and one Routh test; importing numba and loading its cached machine
code costs far more than running the same functions in the interpreter.
:func:`call` runs the *same source* (:mod:`._compiled` executed with a
``numba.njit`` that returns the function unchanged) for batches of at most
:data:`SMALL` rows and the compiled functions otherwise.  The arithmetic is
IEEE double precision either way (the kernels use no ``fastmath``); where
Python raises instead of producing ``inf``/``nan`` (numba's
``error_model="numpy"``) the call is repeated by the compiled kernel, so the
result never depends on the route (tests/analysis/test_map_speed.py compares both on
random input, bit for bit).
"""

from __future__ import annotations

import importlib.util
import types
from typing import Any

from ..codegen.stability import plain_module

__all__ = ["SMALL", "twin", "call"]

#: Largest batch run as plain Python.
SMALL = 4
_TWIN: list[types.ModuleType] = []


def twin() -> types.ModuleType:
    """:mod:`._compiled` executed as plain Python (built once per process)."""
    if not _TWIN:
        spec = importlib.util.find_spec("brakesqueal.analysis._compiled")
        assert spec is not None and spec.loader is not None and spec.origin is not None
        src = spec.loader.get_source(spec.name)  # type: ignore[attr-defined]
        assert src is not None and "\nimport numba\n" in src and src.rstrip().endswith("_guard()")
        _TWIN.append(plain_module(src.rstrip()[: -len("_guard()")], spec.origin, "brakesqueal.analysis"))
    return _TWIN[0]


def call(name: str, rows: int, *args: Any) -> None:
    """Run kernel ``name`` of :mod:`._compiled` on ``args`` (outputs in place): plain Python for ``rows <= SMALL``."""
    if rows <= SMALL:
        import numpy as np

        try:
            with np.errstate(all="ignore"):
                getattr(twin(), name)(*args)
            return
        except (ArithmeticError, ValueError):  # numba gives inf/nan here: let the compiled kernel do it
            pass
    from . import _compiled

    getattr(_compiled, name)(*args)
