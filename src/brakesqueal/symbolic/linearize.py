r"""Symbolic linearization about the silent motion (paper eqs. 46-48).

The residuals ``psi`` (eq. 44) and ``g`` (eqs. 33-34) depend on
``x = (q_m, q_mdot, q_mddot, l, ldot)``.  Treatment of the pads' tangential
rates (documented in ``docs/theory.md``): the massless pads are *quasi-static*,
``ldot := 0`` in the relative sliding velocities and normal-force rates, and
``l`` follows ``(q_m, q_mdot)`` through ``g = 0`` (implicit function theorem).
Linearizing about the silent motion ``(q_m0, l0)`` gives eq. (47) with

* ``Mbar = psi_ddq``,
* ``Dbar = psi_dq - psi_l g_l^{-1} g_dq``,
* ``Kbar = psi_q  - psi_l g_l^{-1} g_q``

(eq. 48 with ``l`` eliminated).  At the trivial silent motion
``psi_dl = g_dl = 0`` exactly, so the treatment of ``ldot`` does not matter to
first order there; this is verified symbolically in the tests.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Literal

from .backend import get_backend
from .model import STATE_SYMBOLS, SymbolicEquations, derive_equations

__all__ = [
    "BLOCKS",
    "CASES",
    "jacobian_blocks",
    "trivial_blocks",
    "linear_matrices",
    "ClosedForm",
    "closed_form",
]

Case = Literal["general", "symmetric", "asymmetric-friction", "minimal"]
CASES: tuple[str, ...] = ("general", "symmetric", "asymmetric-friction", "minimal")

#: Names of the Jacobian blocks, ``<residual>_<variable group>``.
BLOCKS: tuple[str, ...] = ("psi_q", "psi_dq", "psi_ddq", "psi_l", "psi_dl", "g_q", "g_dq", "g_l", "g_dl")
_GROUPS = {"q": (0, 1), "dq": (2, 3), "ddq": (4, 5), "l": (6, 7), "dl": (8, 9)}


def jacobian_blocks(eq: SymbolicEquations) -> dict[str, Any]:
    """Exact symbolic Jacobians of ``psi`` and ``g`` by variable group.

    The partial derivatives of eq. (48), taken for the full state before any
    operating point is substituted, plus those with respect to the pads'
    tangential deformations ``l`` and rates ``ldot``.

    Parameters
    ----------
    eq : SymbolicEquations
        The nonlinear equations (:func:`~brakesqueal.symbolic.model.derive_equations`).

    Returns
    -------
    dict
        The nine blocks of :data:`BLOCKS`, ``{"psi_q": 2×2, "psi_dq": ..., "g_dl": 2×2}``:
        block ``<r>_<grp>`` is ``d r / d grp`` for the residual ``r`` in
        ``psi`` (eq. 44), ``g`` (eqs. 33-34) and the group ``grp`` in ``q``
        ``(q1, q2)``, ``dq``, ``ddq``, ``l`` ``(l1, l2)``, ``dl``; matrices of
        the backend of ``eq``, functions of the state and parameters.
    """
    sm = get_backend(eq.backend)  # type: ignore[arg-type]
    out = {}
    for res_name, res in (("psi", eq.psi), ("g", eq.g)):
        for grp, idx in _GROUPS.items():
            syms = sm.Matrix([eq.state[STATE_SYMBOLS[i]] for i in idx])
            out[f"{res_name}_{grp}"] = res.jacobian(syms)
    return out


def trivial_blocks(eq: SymbolicEquations) -> dict[str, Any]:
    """Jacobian blocks evaluated at the trivial silent motion (all states zero).

    The trivial silent motion ``q_m0 = 0``, ``l0 = 0`` exists when
    ``mu1 h10 = mu2 h20`` (eq. 49); the blocks are then those of eq. (48).

    Parameters
    ----------
    eq : SymbolicEquations
        The nonlinear equations.

    Returns
    -------
    dict
        The blocks of :func:`jacobian_blocks` with every state symbol set to
        0: 2 × 2 matrices of the parameters only.
    """
    zero = {s: 0 for s in eq.state_vector}
    return {k: v.subs(zero) for k, v in jacobian_blocks(eq).items()}


def linear_matrices(blocks: dict[str, Any], sm: Any) -> tuple[Any, Any, Any]:
    """``(Mbar, Dbar, Kbar)`` from Jacobian blocks (quasi-static pads).

    Works for symbolic blocks (backend ``sm``) evaluated at the silent motion.
    The pads' deformations ``l`` are eliminated through ``g = 0``:
    ``Mbar = psi_ddq``, ``Dbar = psi_dq - psi_l g_l^-1 g_dq`` and
    ``Kbar = psi_q - psi_l g_l^-1 g_q`` (eq. 48 with ``l`` eliminated; the
    ``dl`` blocks are not used).  ``g_l^-1`` is written out as the adjugate
    over the determinant (skipped when ``g_l`` is the identity).

    Parameters
    ----------
    blocks : dict
        Jacobian blocks as returned by :func:`jacobian_blocks` or
        :func:`trivial_blocks`; needs ``psi_q``, ``psi_dq``, ``psi_ddq``,
        ``psi_l``, ``g_q``, ``g_dq`` and a 2 × 2 ``g_l``.
    sm : module
        The symbolic backend of the blocks (``symengine`` or ``sympy``), as
        returned by :func:`~brakesqueal.symbolic.backend.get_backend`.

    Returns
    -------
    Mbar, Dbar, Kbar : Matrix
        The 2 × 2 matrices of eq. (47), unsimplified.
    """
    g_l = blocks["g_l"]
    if g_l == sm.eye(2):
        gl_inv = g_l
    else:
        a, b, c, d = g_l[0, 0], g_l[0, 1], g_l[1, 0], g_l[1, 1]
        det = a * d - b * c
        gl_inv = sm.Matrix([[d, -b], [-c, a]]) / det
    P = blocks["psi_l"] * gl_inv
    M = blocks["psi_ddq"]
    D = blocks["psi_dq"] - P * blocks["g_dq"]
    K = blocks["psi_q"] - P * blocks["g_q"]
    return M, D, K


@dataclass(frozen=True)
class ClosedForm:
    """Closed-form ``Mbar, Dbar, Kbar`` about the trivial silent motion (SymPy).

    Attributes
    ----------
    case : str
        One of :data:`CASES`.
    M, D, K : sympy.Matrix
        Simplified matrices of eq. (47), in the paper's parameter names
        (``k_ip1``, ``k_ip2`` rather than compliances; ``h`` and ``mu`` / ``k``
        / ``d`` / ``k_ip`` where the case ties parameters).
    assumptions : str
        The parameter relations of the case, with equation numbers.
    symbols : dict
        The SymPy symbols used, by name (all positive).
    """

    case: str
    M: Any
    D: Any
    K: Any
    assumptions: str
    symbols: dict[str, Any]


_ASSUMPTIONS = {
    "general": "q_m0 = 0 (valid when mu1*h10 = mu2*h20, eq. 49); all other parameters independent",
    "symmetric": "h10 = h20 = h/2, mu1 = mu2 = mu (eq. 50); k1, k2, d1, d2, k_ip1, k_ip2 independent (eqs. 51-53)",
    "asymmetric-friction": "k1 = k2 = k, d1 = d2 = d, k_ip1 = k_ip2 = k_ip (eq. 56), "
    "mu1*h10 = mu2*h20 = h*mu1*mu2/(mu1+mu2) (eqs. 57-58) (eqs. 59-61)",
    "minimal": "eq. 50 and k1 = k2 = k, d1 = d2 = d, 1/k_ip1 = 1/k_ip2 = 0 (eq. 55) (eq. 54)",
}


def case_substitutions(case: str, S: dict[str, Any]) -> dict[Any, Any]:
    """SymPy substitutions (compliance symbols → ``1/k_ip``) that define a case."""
    import sympy as sp

    h, mu, k, d, kip = (sp.Symbol(n, positive=True) for n in ("h", "mu", "k", "d", "k_ip"))
    S.update({"h": h, "mu": mu, "k": k, "d": d, "k_ip": kip})
    base = {S["c_ip1"]: 1 / S["k_ip1"], S["c_ip2"]: 1 / S["k_ip2"]}
    if case == "general":
        return base
    if case == "symmetric":
        return {**base, S["h10"]: h / 2, S["h20"]: h / 2, S["mu1"]: mu, S["mu2"]: mu}
    if case == "asymmetric-friction":
        m1, m2 = S["mu1"], S["mu2"]
        return {
            S["c_ip1"]: 1 / kip, S["c_ip2"]: 1 / kip, S["k1"]: k, S["k2"]: k, S["d1"]: d, S["d2"]: d,
            S["h10"]: h * m2 / (m1 + m2), S["h20"]: h * m1 / (m1 + m2),
        }  # fmt: skip
    if case == "minimal":
        return {
            S["c_ip1"]: 0, S["c_ip2"]: 0, S["k1"]: k, S["k2"]: k, S["d1"]: d, S["d2"]: d,
            S["h10"]: h / 2, S["h20"]: h / 2, S["mu1"]: mu, S["mu2"]: mu,
        }  # fmt: skip
    raise ValueError(f"case must be one of {', '.join(CASES)}; got {case!r}")


@lru_cache(maxsize=8)
def closed_form(case: Case = "general") -> ClosedForm:
    """Closed-form linear matrices of a case about the trivial silent motion.

    The blocks are derived with symengine, then converted to SymPy with
    positive symbols, the case's parameter relations substituted and each
    entry simplified (``cancel`` then ``factor_terms``).

    Parameters
    ----------
    case : {"general", "symmetric", "asymmetric-friction", "minimal"}
        See :data:`CASES` and ``ClosedForm.assumptions``.

    Returns
    -------
    ClosedForm
    """
    import sympy as sp

    if case not in CASES:
        raise ValueError(f"case must be one of {', '.join(CASES)}; got {case!r}")
    eq = derive_equations("symengine")
    se = get_backend("symengine")
    M, D, K = linear_matrices(trivial_blocks(eq), se)
    names = [str(s) for s in eq.param_vector] + ["k_ip1", "k_ip2"]
    S = {n: sp.Symbol(n, positive=True) for n in names}
    S["h10"], S["h20"] = sp.Symbol("h10", real=True), sp.Symbol("h20", real=True)
    subs = case_substitutions(case, S)

    def conv(m: Any) -> Any:
        out = sp.Matrix(sp.sympify(m)).xreplace({sp.Symbol(n): S[n] for n in names})
        return out.xreplace(subs).applyfunc(lambda e: sp.factor_terms(sp.cancel(e)))

    return ClosedForm(case=case, M=conv(M), D=conv(D), K=conv(K), assumptions=_ASSUMPTIONS[case], symbols=S)
