r"""Symbolic linearization about the trivial silent motion (paper eqs. 46-48), for any model.

The residuals ``R`` (eq. 44) and ``G`` (eqs. 33-34) depend on
``x = (Q, Qdot, Qddot, L, Ldot)``.  At the zero state (the trivial silent
motion, e.g. ``mu1*h10 = mu2*h20`` for the paper's model, eq. 49) the pads'
rate blocks ``R_Ldot`` and ``G_Ldot`` vanish identically for rate-independent
friction (verified symbolically here and in the tests), so ``L`` follows
``(Q, Qdot)`` through ``G = 0`` exactly to first order and eq. (47) holds with

* ``Mbar = R_Qddot``,
* ``Dbar = R_Qdot - R_L G_L^{-1} G_Qdot``,
* ``Kbar = R_Q  - R_L G_L^{-1} G_Q``

(eq. 48 with ``L`` eliminated).  For a rate-dependent friction law the rate
blocks do not vanish and :func:`model_closed_form` returns them too (a
descriptor system; see :mod:`brakesqueal.analysis.linear`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import TYPE_CHECKING, Any, Literal, cast

from ..errors import ParameterError
from .backend import get_backend

if TYPE_CHECKING:
    from ..model.components import ModelSpec
    from .assemble import Equations
    from .model import SymbolicEquations


def _unknown_case(case: object) -> ParameterError:
    """The error for an unknown closed-form case (a ``ValueError`` too)."""
    from ..suggest import did_you_mean

    return ParameterError(f"case must be one of {', '.join(CASES)}; got {case!r}{did_you_mean(str(case), CASES)}",
                          parameter="case")

__all__ = [
    "BLOCKS",
    "CASES",
    "jacobian_blocks",
    "trivial_blocks",
    "linear_matrices",
    "ClosedForm",
    "closed_form",
    "model_closed_form",
    "simplify_entry",
]

Case = Literal["general", "symmetric", "asymmetric-friction", "minimal"]
CASES: tuple[str, ...] = ("general", "symmetric", "asymmetric-friction", "minimal")

#: Names of the Jacobian blocks of the paper's model, ``<residual>_<variable group>``.
BLOCKS: tuple[str, ...] = ("psi_q", "psi_dq", "psi_ddq", "psi_l", "psi_dl", "g_q", "g_dq", "g_l", "g_dl")
_GROUPS = ("Q", "dQ", "ddQ", "L", "dL")
_OLD = {"R": "psi", "G": "g", "Q": "q", "dQ": "dq", "ddQ": "ddq", "L": "l", "dL": "dl"}


def simplify_entry(e: Any) -> Any:
    """``factor_terms(cancel(e))`` with every exponential kept as written: no ``exp`` moves to a denominator.

    SymPy's ``cancel`` writes ``exp(-x)`` as ``1/exp(x)`` (``as_numer_denom``)
    and multiplies the other terms by ``exp(x)``.  Generated from that, a
    decaying term such as the Stribeck law's ``exp(-v/v_s)`` at a sliding
    speed of many ``v_s`` evaluates ``exp`` of a large positive argument,
    which overflows to ``inf/inf = nan``.  Here each exponential is a
    positive atom while the rest is cancelled, so the result evaluates only
    the exponentials of the model (a friction law's decay: at most 1).
    Without exponentials this is ``factor_terms(cancel(e))`` itself.

    Parameters
    ----------
    e : sympy.Expr
        The expression (SymPy; symbols with their signs).

    Returns
    -------
    sympy.Expr
        Equal to ``e``.
    """
    import sympy as sp

    e = sp.sympify(e)
    atoms = e.atoms(sp.exp)
    if not atoms:
        return sp.factor_terms(sp.cancel(e))
    # one atom per exponent (cancelled, so that equal exponents written differently share it)
    exps = {a: sp.exp(sp.cancel(a.args[0])) for a in atoms}
    mask = {x: sp.Dummy("E", positive=True) for x in set(exps.values())}
    masked = e.xreplace({a: mask[x] for a, x in exps.items()})
    return sp.factor_terms(sp.cancel(masked)).xreplace({d: x for x, d in mask.items()})


def _equations(eq: Equations | SymbolicEquations) -> Equations:
    """The general :class:`~.assemble.Equations` behind ``eq`` (also accepts the paper view of :mod:`.model`)."""
    return cast("Equations", getattr(eq, "equations", eq))


def jacobian_blocks(eq: Equations | SymbolicEquations) -> dict[str, Any]:
    """Exact symbolic Jacobians of ``R`` and ``G`` by variable group.

    Parameters
    ----------
    eq : Equations or SymbolicEquations
        The nonlinear equations (:func:`~brakesqueal.symbolic.assemble.build_equations`,
        or the paper view :func:`~brakesqueal.symbolic.model.derive_equations`).

    Returns
    -------
    dict
        Blocks ``<r>_<grp>`` = ``d r / d grp`` for ``r`` in ``R``, ``G`` and
        ``grp`` in ``Q, dQ, ddQ, L, dL`` (``G_*`` only when the model has
        pad deformations ``L``).  For the paper's model the classic keys
        ``psi_q, ..., g_dl`` of :data:`BLOCKS` are present too.
    """
    e = _equations(eq)
    sm = get_backend(e.backend)
    out: dict[str, Any] = {}
    groups = {"Q": e.Q, "dQ": e.dQ, "ddQ": e.ddQ, "L": e.L, "dL": e.dL}
    for res_name, res in (("R", e.R), ("G", e.G)):
        if res is None:
            continue
        for grp, syms in groups.items():
            key = f"{res_name}_{grp}"
            out[key] = res.jacobian(sm.Matrix(syms)) if syms else sm.zeros(res.rows, 0)
            if e.spec.name == "paper":
                out[f"{_OLD[res_name]}_{_OLD[grp]}"] = out[key]
    return out


def trivial_blocks(eq: Equations | SymbolicEquations) -> dict[str, Any]:
    """The blocks of :func:`jacobian_blocks` at the zero state (the trivial silent motion).

    Parameters
    ----------
    eq : Equations or SymbolicEquations
        The nonlinear equations.

    Returns
    -------
    dict
        Functions of the parameters only.
    """
    e = _equations(eq)
    zero = {s: 0 for s in e.x}
    return {k: v.subs(zero) for k, v in jacobian_blocks(eq).items()}


def linear_matrices(blocks: dict[str, Any], sm: Any) -> tuple[Any, Any, Any]:
    """``(Mbar, Dbar, Kbar)`` from Jacobian blocks with the pad deformations eliminated through ``G = 0``.

    ``Mbar = R_ddQ``, ``Dbar = R_dQ - R_L G_L^-1 G_dQ``, ``Kbar = R_Q - R_L G_L^-1 G_Q``
    (eq. 48 with ``L`` eliminated; the ``dL`` blocks are not used, which is
    exact where they vanish, see the module docstring).

    Parameters
    ----------
    blocks : dict
        Blocks as returned by :func:`jacobian_blocks` or :func:`trivial_blocks`.
    sm : module
        The symbolic backend of the blocks.

    Returns
    -------
    Mbar, Dbar, Kbar : Matrix
        ``n × n``, unsimplified.
    """
    M, D, K = blocks["R_ddQ"], blocks["R_dQ"], blocks["R_Q"]
    if "G_L" not in blocks or blocks["G_L"].rows == 0:
        return M, D, K
    G_L = blocks["G_L"]
    inv = G_L if G_L == sm.eye(G_L.rows) else G_L.inv()
    P = blocks["R_L"] * inv
    return M, D - P * blocks["G_dQ"], K - P * blocks["G_Q"]


@dataclass(frozen=True)
class ClosedForm:
    """Closed-form ``Mbar, Dbar, Kbar`` about the trivial silent motion (SymPy).

    Attributes
    ----------
    case : str
        One of :data:`CASES`, or ``"model:<name>"`` for :func:`model_closed_form`.
    M, D, K : sympy.Matrix
        Simplified matrices of eq. (47), in the paper's parameter names
        (``k_ip1``, ``k_ip2`` rather than compliances; ``h`` and ``mu`` / ``k``
        / ``d`` / ``k_ip`` where the case ties parameters).
    assumptions : str
        The parameter relations of the case, with equation numbers.
    symbols : dict
        The SymPy symbols used, by name (all positive).
    coords : tuple of str
        Names of the rows and columns.
    rate_blocks : dict
        For rate-dependent friction: the non-vanishing blocks ``R_L``,
        ``R_dL``, ``G_Q``, ``G_dQ``, ``G_L``, ``G_dL`` of the pads that keep
        their first-order dynamics (empty otherwise).
    """

    case: str
    M: Any
    D: Any
    K: Any
    assumptions: str
    symbols: dict[str, Any]
    coords: tuple[str, ...] = ("q1", "q2")
    rate_blocks: dict[str, Any] = field(default_factory=dict)


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
    raise _unknown_case(case)


@lru_cache(maxsize=8)
def closed_form(case: Case = "general") -> ClosedForm:
    """Closed-form linear matrices of a case about the trivial silent motion.

    The blocks are derived with symengine, then converted to SymPy with
    positive symbols, the case's parameter relations substituted and each
    entry simplified (``cancel`` then ``factor_terms``, :func:`simplify_entry`).

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
        raise _unknown_case(case)
    from ..model.library import get_model
    from .assemble import build_equations

    eq = build_equations(get_model("paper"), "symengine")
    se = get_backend("symengine")
    M, D, K = linear_matrices(trivial_blocks(eq), se)
    names = list(eq.param_names) + ["k_ip1", "k_ip2"]
    S = {n: sp.Symbol(n, positive=True) for n in names}
    S["h10"], S["h20"] = sp.Symbol("h10", real=True), sp.Symbol("h20", real=True)
    subs = case_substitutions(case, S)

    def conv(m: Any) -> Any:
        out = sp.Matrix(sp.sympify(m)).xreplace({sp.Symbol(n): S[n] for n in names})
        return out.xreplace(subs).applyfunc(simplify_entry)

    return ClosedForm(case=case, M=conv(M), D=conv(D), K=conv(K), assumptions=_ASSUMPTIONS[case], symbols=S)


def model_closed_form(spec: ModelSpec) -> ClosedForm:
    """Symbolic ``M, D, K`` of any model about the zero state (the silent motion when it is trivial).

    Numeric component fields enter as numbers, named ones as positive SymPy
    symbols of the same name (``h_upper``/``h_lower`` names as real
    symbols); tangential compliances are written back as ``1/k_ip``.  Where
    a pad's rate blocks vanish identically (rate-independent friction) its
    deformation is eliminated exactly; otherwise the pad keeps its
    first-order dynamics and its blocks are returned in ``rate_blocks``.

    Parameters
    ----------
    spec : ModelSpec
        The model (for ``paper`` the result equals ``closed_form("general")``,
        whose special cases are eqs. (51)-(53) and (59)-(61)).

    Returns
    -------
    ClosedForm
        ``case = "model:<name>"``; entries simplified with ``cancel`` and
        ``factor_terms`` (:func:`simplify_entry`: exponentials stay in the numerators).
    """
    import sympy as sp

    from .assemble import build_equations

    eq = build_equations(spec, "symengine")
    blocks = trivial_blocks(eq)
    real = {n for n in (spec.disk.h_upper, spec.disk.h_lower) if isinstance(n, str)}
    S = {n: (sp.Symbol(n, real=True) if n in real else sp.Symbol(n, positive=True)) for n in spec.parameters}
    back = {}
    for name, pn in zip(spec.parameters, eq.param_names):
        back[sp.Symbol(pn)] = 1 / S[name] if pn != name else S[name]

    def conv(m: Any) -> Any:
        return sp.Matrix(sp.sympify(m)).xreplace(back).applyfunc(simplify_entry)

    sb = {k: conv(v) for k, v in blocks.items() if k[0] in "RG" and "_" in k and not k.startswith(("psi", "g_"))}
    n = len(eq.coords)
    M, D, K = sb["R_ddQ"], sb["R_dQ"], sb["R_Q"]
    rate: dict[str, Any] = {}
    if eq.G is not None:
        m = len(eq.algebraic)
        dyn = [j for j in range(m) if any(sp.simplify(e) != 0 for e in list(sb["R_dL"][:, j]) + list(sb["G_dL"][:, j])
                                            + list(sb["G_dL"][j, :]))]
        qs = [j for j in range(m) if j not in dyn]
        if qs:
            GL = sb["G_L"].extract(qs, qs)
            P = sb["R_L"].extract(list(range(n)), qs) * GL.inv()
            D = (D - P * sb["G_dQ"].extract(qs, list(range(n)))).applyfunc(simplify_entry)
            K = (K - P * sb["G_Q"].extract(qs, list(range(n)))).applyfunc(simplify_entry)
        if dyn:
            rows, alln = list(range(n)), list(range(n))
            rate = {"pads": tuple(eq.algebraic[j] for j in dyn),
                    "R_L": sb["R_L"].extract(rows, dyn), "R_dL": sb["R_dL"].extract(rows, dyn),
                    "G_Q": sb["G_Q"].extract(dyn, alln), "G_dQ": sb["G_dQ"].extract(dyn, alln),
                    "G_L": sb["G_L"].extract(dyn, dyn), "G_dL": sb["G_dL"].extract(dyn, dyn)}
    return ClosedForm(case=f"model:{spec.name}", M=M, D=D, K=K,
                      assumptions="zero state Q = 0, L = 0 (the silent motion when the residuals vanish there)",
                      symbols=S, coords=eq.coords, rate_blocks=rate)
