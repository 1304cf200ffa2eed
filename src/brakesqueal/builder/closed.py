"""Symbolic ``M, D, K`` of a built model about the zero state, and resolving ``--model`` arguments."""

from __future__ import annotations

import os
from typing import Any

from ..errors import ParameterError
from .assemble import build_equations, compliance_name
from .components import ModelSpec
from .library import MODELS, get_model
from .toml_io import load_model

__all__ = ["model_closed_form", "resolve_model"]


def resolve_model(arg: str) -> ModelSpec:
    """A model from a TOML file path or a built-in model name (the ``--model`` option).

    Parameters
    ----------
    arg : str
        Path of a model TOML file (used when the path exists or ends with
        ``.toml``; see :func:`~brakesqueal.builder.toml_io.load_model`), else
        the name of a built-in model of :data:`~brakesqueal.builder.library.MODELS`.

    Returns
    -------
    ModelSpec
        The validated model.

    Raises
    ------
    ParameterError
        If ``arg`` is neither a model file nor a built-in model name, or the
        file cannot be read or describes an invalid model.
    """
    if os.path.exists(arg) or arg.endswith(".toml"):
        return load_model(arg)
    if arg in MODELS:
        return get_model(arg)
    raise ParameterError(f"--model '{arg}' is neither a model file nor a built-in model ({', '.join(MODELS)})")


def model_closed_form(spec: ModelSpec) -> tuple[Any, Any, Any, tuple[str, ...]]:
    """SymPy ``(M, D, K, coords)`` about the zero state (the silent motion when it is trivial).

    The Jacobians of the assembled residuals at ``Q = Qdot = Qddot = L = 0``,
    with the quasi-static deformations ``L`` eliminated as in
    :func:`~brakesqueal.builder.numeric.linearize_model` (eq. 48
    generalized).  They are the linearization only when the zero state is
    the silent motion, e.g. for the paper's pads when
    ``mu1 h10 = mu2 h20`` (eq. 49).  For ``paper-2dof`` they equal the
    ``"general"`` case of :func:`brakesqueal.symbolic.closed_form`, whose
    special cases are eqs. (51)-(53) and (59)-(61).

    Parameters
    ----------
    spec : ModelSpec
        The model (numeric component fields enter as numbers, named ones as
        positive SymPy symbols of the same name).

    Returns
    -------
    M, D, K : sympy.Matrix, shape (n, n)
        Mass, damping and stiffness matrices.  Tangential compliances are
        written back as ``1/k_ip``; each entry is simplified with ``cancel``
        and ``factor_terms``.
    coords : tuple of str
        Names of the ``n`` coordinates (rows and columns).
    """
    import symengine as se
    import sympy as sp

    eq = build_equations(spec)
    n, m = len(eq.coords), len(eq.algebraic)
    X = se.Matrix(eq.x)
    zero = {s: 0 for s in eq.x}
    JR = eq.R.jacobian(X).subs(zero)
    names = [str(s) for s in eq.params]
    S = {nm: sp.Symbol(nm, positive=True) for nm in names}
    back = {S[compliance_name(k)]: 1 / sp.Symbol(k, positive=True) for k in spec.stiffness_names()}

    def conv(mat: Any) -> Any:
        out = sp.Matrix(sp.sympify(mat)).xreplace({sp.Symbol(k): v for k, v in S.items()})
        return out.xreplace(back)

    R = conv(JR)
    M, D, K = R[:, 2 * n : 3 * n], R[:, n : 2 * n], R[:, :n]
    if m:
        JG = conv(eq.G.jacobian(X).subs(zero))
        P = R[:, 3 * n :] * JG[:, 3 * n :].inv()
        D = D - P * JG[:, n : 2 * n]
        K = K - P * JG[:, :n]
    simp = lambda e: sp.factor_terms(sp.cancel(e))  # noqa: E731
    return M.applyfunc(simp), D.applyfunc(simp), K.applyfunc(simp), eq.coords
