"""Analysis layer: silent motion, linear models, eigen-analysis, stability maps, crossings, critical speeds.

The names are loaded on first use (PEP 562), so that importing one light
module (e.g. :mod:`.linear` for ``brakesqueal linearize``) does not import the
compiled stability kernels (numba).
"""

from __future__ import annotations

import importlib
import sys
import types
from typing import Any

#: Public name -> submodule that defines it.
_WHERE = {
    "SilentMotion": "equilibrium",
    "silent_motion": "equilibrium",
    "LinearModel": "linear",
    "linearize": "linear",
    "pad_rate_eigenvalues": "linear",
    "Axis": "stability",
    "EigenAnalysis": "stability",
    "ParameterSpace": "stability",
    "PointVerdict": "stability",
    "Verdict": "stability",
    "Verdicts": "stability",
    "decide": "stability",
    "write_map": "stability",
    "critical_speeds": "stability",
    "critical_speeds_many": "stability",
    "crossings": "stability",
    "eigen_analysis": "stability",
    "evaluate": "stability",
    "evaluate_point": "stability",
    "stability_map": "stability",
}

__all__ = list(_WHERE)


def __getattr__(name: str) -> Any:
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


class _Package(types.ModuleType):
    """Keeps public functions named like a submodule (``crossings``) when the import system binds the submodule."""

    def __setattr__(self, name: str, value: Any) -> None:
        if name in _WHERE and isinstance(value, types.ModuleType):
            value = getattr(value, name)
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package
