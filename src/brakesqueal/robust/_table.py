"""The exact polynomials a robust-box decision needs, as dense coefficient tensors (built once, kept on disk).

For a parameter space with the box names symbolic, the quartic
``det(λ²M + λD + K)`` of the trivial silent motion is ``Σ a_i λ^i`` with
``a_i = N_i / Den`` (:func:`brakesqueal.symbolic.stability_forms.quartic_numerators`:
exact polynomials over QQ in the box names, ties applied).  The table holds
``Den``, ``N_0 .. N_4`` and the Hurwitz determinant ``H3 = N1 (N3 N2 - N4 N1)
- N3² N0`` as dense tensors of double intervals (each exact rational rounded
outward), so that a decision needs no computer algebra after the first run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace

__all__ = ["PolyTable", "POLY_NAMES", "poly_table"]

#: The polynomials of a table, in order.
POLY_NAMES = ("den", "N0", "N1", "N2", "N3", "N4", "H3")


@dataclass(frozen=True)
class PolyTable:
    """Dense coefficient tensors of :data:`POLY_NAMES` in the box names.

    Attributes
    ----------
    names : tuple of str
        The box names (tensor axes 1..k, in this order); a shifted table has one more axis, the shift ``σ``
        (last).
    coef : ndarray, shape (7, D_1, ..., D_k)
        Nearest doubles of the exact coefficients (``coef[p, e_1, ..., e_k]`` multiplies ``Π x_j^e_j``).
    rad : ndarray
        Bounds on ``|exact - coef|`` (0 where the coefficient is a double).
    """

    names: tuple[str, ...]
    coef: np.ndarray
    rad: np.ndarray


def _outward(v: Fraction) -> tuple[float, float]:
    """Nearest double of an exact rational and a bound on the difference."""
    f = float(v)
    if not math.isfinite(f):
        raise OverflowError("coefficient out of the double range")
    return f, 0.0 if Fraction(f) == v else math.ulp(f) if f != 0 else 5e-324


def _terms(poly: Any, nax: int, consts: tuple[Any, ...]) -> list[tuple[tuple[int, ...], float, float]]:
    """``(exponents, nearest double, radius)`` of a ring element, constants (π, ...) evaluated with 60 digits."""
    out: dict[tuple[int, ...], Any] = {}
    exact = not consts
    if exact:
        for mon, c in poly.terms():
            key = tuple(int(e) for e in mon[:nax])
            out[key] = out.get(key, Fraction(0)) + Fraction(int(c.numerator), int(c.denominator))
        rows = []
        for key, v in out.items():
            if v != 0:
                f, r = _outward(v)
                rows.append((key, f, r))
        return rows
    import mpmath
    import sympy as sp

    with mpmath.workdps(60):
        cv = [mpmath.mpf(sp.N(c, 70)) for c in consts]
        for mon, c in poly.terms():
            v = mpmath.mpf(int(c.numerator)) / int(c.denominator)
            for g, k in zip(cv, mon[nax:]):
                v *= g ** int(k)
            key = tuple(int(e) for e in mon[:nax])
            out[key] = out.get(key, 0) + v
        rows = []
        for key, v in out.items():
            f = float(v)
            if f != 0 or v != 0:
                # 60 digits: the value is within a tiny fraction of an ulp of f; two ulps cover it
                rows.append((key, f, 2 * math.ulp(f) if f != 0 else 5e-324))
    return rows


def _shifted(qn: Any) -> tuple[Any, ...]:
    """``Den, N'_0 .. N'_4, H3'`` of ``Σ N_i (λ + σ)^i`` with the shift ``σ`` a generator after the names."""
    import sympy as sp
    from sympy.polys.rings import ring

    R0 = qn.N[0].ring
    nax = len(qn.names)
    sigma = sp.Symbol("robust_sigma")
    syms = list(R0.symbols)
    R1, *gens = ring([*syms[:nax], sigma, *syms[nax:]], R0.domain)
    g = gens[nax]
    N = [p.set_ring(R1) for p in qn.N]
    S = [sum((math.comb(i, k) * g ** (i - k) * N[i] for i in range(k, 5)), R1.zero) for k in range(5)]
    h3 = S[1] * (S[3] * S[2] - S[4] * S[1]) - S[3] ** 2 * S[0]
    return (qn.den.set_ring(R1), *S, h3)


def _build(engine: Engine, space: ParameterSpace, names: tuple[str, ...], shifted: bool) -> dict[str, Any] | None:
    qn = engine.quartic(space, names)
    if qn is None:
        return None
    n0, n1, n2, n3, n4 = qn.N
    polys = _shifted(qn) if shifted else (qn.den, n0, n1, n2, n3, n4, qn.hurwitz())
    nax = len(names) + int(shifted)
    try:
        rows = [_terms(p, nax, tuple(qn.constants)) for p in polys]
    except OverflowError:
        return None
    return {"names": list(names),
            "polys": [[[list(k), f.hex(), float(r).hex()] for k, f, r in rs] for rs in rows]}


def poly_table(engine: Engine, space: ParameterSpace, names: tuple[str, ...], shifted: bool = False
               ) -> PolyTable | None:
    """The table of ``space`` with ``names`` symbolic (``None`` where the closed-form route does not apply).

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The parameter space (ties apply).
    names : tuple of str
        Settable names of ``space`` (the box's dimensions).
    shifted : bool
        The polynomials of ``p(λ + σ)`` with the shift ``σ`` as a last axis (Hurwitz for every point of a box
        ⇔ every root has ``Re λ < σ`` there).

    Returns
    -------
    PolyTable or None
        ``None`` when the model has no closed form, the silent motion is not identically trivial over the
        names (a zero-state residual does not vanish identically under the ties) or the dependence is not
        rational.
    """
    from ..codegen.stability import disk_json

    names = tuple(names)
    if not engine.caps.closed_form:
        return None
    # the values of the box names do not enter the polynomials: key the table without them
    base = space
    ident = f"robust-v1|{engine.key}|{base.key()}|{names!r}|{shifted}"
    data = disk_json("robust", ident, lambda: _build(engine, base, names, shifted), use_cache=engine.use_cache)
    if data is None:
        return None
    nax = len(names) + int(shifted)
    polys = data["polys"]
    degs = [max([0] + [int(t[0][j]) for rs in polys for t in rs]) + 1 for j in range(nax)]
    coef = np.zeros((len(polys), *degs))
    rad = np.zeros_like(coef)
    for p, rs in enumerate(polys):
        for k, f, r in rs:
            coef[(p, *k)] += float.fromhex(f)
            rad[(p, *k)] += float.fromhex(r)
    return PolyTable((*names, "sigma") if shifted else names, coef, rad)
