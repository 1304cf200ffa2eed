"""The paper's 2-DOF model through the compiled-model interface of earlier versions.

Transitional view of :func:`brakesqueal.codegen.compile_model` for the
built-in model ``paper``: the same generated code, with the classic
``contact`` layout ``(F_n1, |v_r1|, h1, F_n2, |v_r2|, h2)`` and
``trivial_matrices(p)`` (the 12 entries of ``Mbar, Dbar, Kbar`` about the
trivial silent motion, NumPy-vectorized).
"""

from __future__ import annotations

import math
import types
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Callable

import numpy as np

__all__ = ["CompiledModel", "compiled_model", "MODEL_KEY"]

#: Cache key of the paper's model (the unified code generator's key).
MODEL_KEY = "paper"


@dataclass(frozen=True)
class CompiledModel:
    """Numeric callables of the paper's general 2-DOF model.

    Attributes
    ----------
    residuals, jacobians : callable
        ``f(x, p)`` of :class:`brakesqueal.codegen.CompiledModel` (paper layout).
    contact : callable
        ``f(x, p) -> (F_n1, |v_r1|, h1, F_n2, |v_r2|, h2)``.
    trivial_matrices : callable
        Vectorized ``f(p) -> 12 entries`` (``Mbar``, ``Dbar``, ``Kbar`` row-major).
    vectorized : module
        All generated functions bound to NumPy.
    source : str
        The generated source.
    model : brakesqueal.codegen.CompiledModel
        The unified compiled model.
    """

    residuals: Callable[..., tuple[float, ...]]
    jacobians: Callable[..., tuple[float, ...]]
    contact: Callable[..., tuple[float, ...]]
    trivial_matrices: Callable[..., tuple[Any, ...]]
    vectorized: types.ModuleType
    source: str
    model: Any = None


@lru_cache(maxsize=2)
def compiled_model(use_cache: bool = True) -> CompiledModel:
    """The compiled paper model (see the module docstring).

    Parameters
    ----------
    use_cache : bool
        Read and write the on-disk cache.

    Returns
    -------
    CompiledModel
    """
    from ..codegen import compile_model
    from ..model.library import get_model

    cm = compile_model(get_model("paper"), use_cache=use_cache)

    def contact(x: Any, p: Any) -> tuple[float, ...]:
        c = cm.contact(x, p)
        k = len(c) // 2
        out = []
        for i in (0, k):
            out += [c[i], math.sqrt(c[i + 1] ** 2 + c[i + 2] ** 2 + c[i + 3] ** 2), c[i + 4]]
        return tuple(out)

    def trivial_matrices(p: Any) -> tuple[Any, ...]:
        M, D, K = cm.zero_linear(p)
        return tuple(X[..., i, j] for X in (M, D, K) for i in range(2) for j in range(2))

    return CompiledModel(residuals=cm.residuals, jacobians=cm.jacobians, contact=contact,
                         trivial_matrices=trivial_matrices, vectorized=cm.vectorized, source=cm.source, model=cm)



def _namespace(namespace: str) -> dict[str, Any]:
    """Globals of generated code: ``sin, cos, tan, sqrt`` from ``math`` or ``numpy``, and ``pi``."""
    lib: Any = math if namespace == "math" else np
    return dict(sin=lib.sin, cos=lib.cos, tan=lib.tan, sqrt=lib.sqrt, pi=math.pi)


def _load(source: str, namespace: str) -> types.ModuleType:
    """Execute generated source in memory with the ``math`` or ``numpy`` functions bound (transitional)."""
    from . import cache

    return cache.load_module("transitional", "numeric.py", lambda: source, use_cache=False,
                             namespace=_namespace(namespace), variant=namespace)
