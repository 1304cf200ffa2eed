"""Choice of the computer-algebra backend used by the symbolic layer.

The symbolic layer is written once against the small API that SymPy and
symengine share (``Symbol``, ``sin``, ``cos``, ``sqrt``, ``Matrix``, ``zeros``,
``eye``, ``diff``, ``subs``, ``jacobian``).  symengine (a C++ core) is the
default because it is two orders of magnitude faster; SymPy is used for
simplification of closed forms, for printing, and as the benchmark baseline.
"""

from __future__ import annotations

from types import ModuleType
from typing import Literal

__all__ = ["Backend", "get_backend"]

Backend = Literal["symengine", "sympy"]


def get_backend(name: Backend = "symengine") -> ModuleType:
    """Return the module implementing the symbolic API.

    Parameters
    ----------
    name : {"symengine", "sympy"}
        Backend name.

    Returns
    -------
    module
        ``symengine`` or ``sympy``.
    """
    if name == "symengine":
        import symengine

        return symengine
    if name == "sympy":
        import sympy

        return sympy
    raise ValueError(f"backend must be 'symengine' or 'sympy'; got {name!r}")
