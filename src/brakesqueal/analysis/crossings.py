r"""Exact stability changes along a 1-D path and critical speeds.

Stability changes only where the characteristic quartic has a root at 0
(``a0 = 0``), a pair on the imaginary axis (``H3 = 0``) or its degree drops
(``a4 = 0``, Orlando's formula); with ``a_i = N_i / Den`` these are real roots
of the exact polynomials ``N_0``, ``N_4``, ``H3(N)`` and ``Den`` in the path
parameter (:func:`~.kernels.quartic_numerators`, rational arithmetic).  Their
roots are isolated *exactly* on the requested range, whatever its width
(:func:`~.robust.isolate_real_roots`: continued fractions over QQ; constants
such as π carried with 80 significant digits), and the verdict is evaluated
exactly between consecutive roots.  Nothing is read from a grid and nothing
overflows, so ``--along k_ip=1e-100:1e100:log`` is as exact as ``1e5:1e10``.

The numeric fallback (non-trivial silent motion, non-rational ties) brackets
sign changes of the certified per-point verdict on a grid and polishes with
Brent's method; it is marked ``exhaustive=False`` (two crossings closer than
the grid spacing can be missed) and points it cannot decide are reported in
``undecided_ranges``.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any

import numpy as np

from ..errors import ParameterError, SilentMotionError
from ..expressions import names_in
from .kernels import QuarticNumerators, critical_speeds_batch, quartic_numerators
from .maps import Axis
from .robust import isolate_real_roots
from .space import ParameterSpace

__all__ = ["crossings", "critical_speeds", "critical_speeds_many", "exact_crossings", "exact_omega_crossings"]

_DIGITS = 80


def _mpf_fraction(v: Any) -> Fraction:
    import mpmath

    sign, man, exp, _ = mpmath.mpf(v)._mpf_
    man = -int(man) if sign else int(man)
    return Fraction(man * 2 ** exp) if exp >= 0 else Fraction(man, 2 ** (-exp))


def _univariate(poly: Any, consts: tuple[Any, ...]) -> tuple[list[Fraction], bool]:
    """Ascending Fraction coefficients in the first generator; ``exact`` False when constants were rounded."""
    import mpmath
    import sympy as sp

    if not consts:
        deg = max((m[0] for m in poly.monoms()), default=0)
        out = [Fraction(0)] * (deg + 1)
        for mon, c in poly.terms():
            out[mon[0]] += Fraction(int(c.numerator), int(c.denominator))
        return out, True
    with mpmath.workdps(_DIGITS + 20):
        cv = [mpmath.mpf(sp.N(c, _DIGITS + 30)) for c in consts]
        acc: dict[int, Any] = {}
        for mon, c in poly.terms():
            v = mpmath.mpf(int(c.numerator)) / int(c.denominator)
            for g, k in zip(cv, mon[1:]):
                v *= g ** k
            acc[mon[0]] = acc.get(mon[0], 0) + v
        deg = max(acc, default=0)
        out = [Fraction(0)] * (deg + 1)
        for k, v in acc.items():
            with mpmath.workdps(_DIGITS):
                out[k] = _mpf_fraction(+v)
    return out, False


def _peval(c: list[Fraction], x: Fraction) -> tuple[Fraction, Fraction]:
    v = Fraction(0)
    a = Fraction(0)
    ax = abs(x)
    for k in range(len(c) - 1, -1, -1):
        v = v * x + c[k]
        a = a * ax + abs(c[k])
    return v, a


def _verdict(N: list[list[Fraction]], x: Fraction, exact: bool) -> int | None:
    """Exact quartic verdict (1 stable, 0 unstable) at ``x``; ``None`` if a sign is not reliable."""
    vals = []
    for c in N:
        v, a = _peval(c, x)
        if not exact and v != 0 and abs(v) < Fraction(1, 10 ** (_DIGITS - 15)) * a:
            return None
        vals.append(v)
    n0, n1, n2, n3, n4 = vals
    if n4 == 0:
        return None
    s = 1 if n4 > 0 else -1
    h = n1 * (n3 * n2 - n4 * n1) - n3 * n3 * n0
    if not exact:
        scale = abs(n1) * (abs(n3 * n2) + abs(n4 * n1)) + n3 * n3 * abs(n0)
        if h != 0 and abs(h) < Fraction(1, 10 ** (_DIGITS - 20)) * scale:
            return None
    if all(s * v > 0 for v in (n0, n1, n2, n3)) and s * h > 0:
        return 1
    return 0


def _split_point(a: Fraction, b: Fraction, log: bool, frac: float = 0.5) -> Fraction:
    if log and a > 0 and b > 4 * a:
        try:
            la, lb = math.log(a), math.log(b)
            x = Fraction(math.exp(la + frac * (lb - la)))
        except (OverflowError, ValueError):
            x = a
        if a < x < b:
            return x
    return a + (b - a) * Fraction(frac).limit_denominator(64)


def exact_crossings(qn: QuarticNumerators, lo: float, hi: float, log: bool = True,
                    valid: Any = None) -> tuple[bool, list[tuple[float, str]], list[tuple[float, float]]]:
    """All stability changes in ``(lo, hi)`` of a one-variable :class:`~.kernels.QuarticNumerators`.

    Parameters
    ----------
    qn : QuarticNumerators
        Numerators in one axis variable.
    lo, hi : float
        The range (taken exactly; any magnitudes).
    log : bool
        Place test points geometrically (only where the verdict is sampled).
    valid : callable, optional
        ``valid(x: float) -> bool``; pieces whose test point is invalid are
        reported as undecided.

    Returns
    -------
    stable_at_start : bool
        Verdict just above ``lo``.
    crossings : list of (float, str)
        Values and directions, ascending.
    undecided : list of (float, float)
        Ranges where no verdict could be established (empty in all but
        pathological cases).
    """
    exact = True
    polys = []
    for p in (*qn.N, qn.hurwitz(), qn.den):
        c, ex = _univariate(p, qn.constants)
        exact &= ex
        polys.append(c)
    N = polys[:5]
    lo_q, hi_q = Fraction(lo), Fraction(hi)
    roots = isolate_real_roots([N[0], N[4], polys[5], polys[6]], lo_q, hi_q)
    iv = [(a, b) for a, b, _ in roots if b > lo_q and a < hi_q and not (a == b == lo_q) and not (a == b == hi_q)]
    # merge isolating intervals closer than 1e-30 relative (a multiple root split by rounded constants)
    merged: list[list[Fraction]] = []
    for a, b in iv:
        if merged and a - merged[-1][1] <= Fraction(1, 10 ** 30) * max(abs(a), abs(merged[-1][1]), Fraction(1, 10 ** 300)):
            merged[-1][1] = max(merged[-1][1], b)
        else:
            merged.append([a, b])
    edges = [lo_q] + [x for a, b in merged for x in (a, b)] + [hi_q]
    pieces = [(edges[2 * k], edges[2 * k + 1]) for k in range(len(merged) + 1)]
    verdicts: list[int | None] = []
    for a, b in pieces:
        v = None
        if b > a:
            for frac in (0.5, 0.25, 0.75, 0.125, 0.875):
                x = _split_point(a, b, log, frac)
                if valid is not None and not valid(float(x)):
                    break
                v = _verdict(N, x, exact)
                if v is not None:
                    break
        verdicts.append(v)
    found: list[tuple[float, str]] = []
    undecided: list[tuple[float, float]] = []
    prev: int | None = verdicts[0]
    start = bool(verdicts[0]) if verdicts[0] is not None else False
    if verdicts[0] is None:
        undecided.append((float(pieces[0][0]), float(pieces[0][1])))
    for k in range(1, len(pieces)):
        v = verdicts[k]
        a, b = merged[k - 1]
        if v is None:
            undecided.append((float(a), float(pieces[k][1])))
        elif prev is None:
            undecided.append((float(pieces[k - 1][1]), float(b)))
        elif v != prev:
            found.append((float((a + b) / 2), "stabilizing" if v == 1 else "destabilizing"))
        if v is not None:
            prev = v
        else:
            prev = None
    return start, found, _merge_ranges(undecided)


def _merge_ranges(r: list[tuple[float, float]]) -> list[tuple[float, float]]:
    out: list[tuple[float, float]] = []
    for a, b in sorted(r):
        if out and a <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], b))
        else:
            out.append((a, b))
    return out


def exact_omega_crossings(p: np.ndarray, lo: float, hi: float
                          ) -> tuple[bool, list[tuple[float, str]], list[tuple[float, float]]]:
    """Exact stability changes along Ω in ``(lo, hi)`` for one parameter vector (trivial silent motion).

    The closed-form matrices are evaluated with the (exact rational) parameter
    values and Ω symbolic; see :func:`exact_crossings`.
    """
    import sympy as sp

    from .kernels import QuarticNumerators, _closed_form_compliance, _quartic_field
    from .space import VECTOR_NAMES

    M, D, K, syms = _closed_form_compliance()
    W = sp.Symbol("X0", positive=True)
    sub = {syms[n]: (W if n == "Omega" else sp.Rational(float(v))) for n, v in zip(VECTOR_NAMES, p)}
    entries = [e.xreplace(sub) for X in (M, D, K) for e in X]
    res = _quartic_field(entries, [W])
    if res is None:  # cannot happen for the closed form
        return False, [], [(lo, hi)]
    Nn, den, consts = res
    return exact_crossings(QuarticNumerators(("Omega",), consts, Nn, den), lo, hi, True)


def _numeric(space: ParameterSpace, axis: Axis, n: int = 801
             ) -> tuple[bool, list[tuple[float, str]], list[tuple[float, float]]]:
    from scipy.optimize import brentq

    from .maps import numeric_point_verdict

    grid = Axis(axis.name, axis.start, axis.stop, n, axis.log).values()

    def verdict(v: float) -> tuple[int, bool, float]:
        code, st, mr, _ = numeric_point_verdict(space, {axis.name: float(v)})
        return code, st, mr

    vs = [verdict(v) for v in grid]
    out: list[tuple[float, str]] = []
    undecided: list[tuple[float, float]] = []
    ok = [c <= 1 for c, _, _ in vs]
    for k in range(n):
        if not ok[k]:
            undecided.append((float(grid[max(k - 1, 0)]), float(grid[min(k + 1, n - 1)])))
    for k in range(n - 1):
        (ca, sa, ma), (cb, sb, mb) = vs[k], vs[k + 1]
        if not (ok[k] and ok[k + 1]) or sa == sb:
            continue
        a, b = grid[k], grid[k + 1]
        x = a
        if math.isfinite(ma) and math.isfinite(mb) and ma * mb < 0:
            x = brentq(lambda v: verdict(v)[2], a, b, xtol=1e-300, rtol=1e-15, maxiter=200)
        out.append((float(x), "stabilizing" if sb else "destabilizing"))
    return bool(vs[0][1]), out, _merge_ranges(undecided)


def _valid_fn(space: ParameterSpace, name: str) -> Any:
    def valid(x: float) -> bool:
        try:
            space.resolve({name: x})
        except (ParameterError, SilentMotionError, ValueError, ZeroDivisionError, OverflowError):
            return False
        return True

    return valid


def crossings(space: ParameterSpace, axis: Axis) -> object:
    """Every value of ``axis.name`` in ``(start, stop)`` where stability of the silent motion changes.

    Stability is that of the linearized equations (47) about the silent
    motion (eq. 46), decided by the Liénard–Chipart criterion on the
    characteristic quartic ``det(λ² Mbar + λ Dbar + Kbar) = a4 λ⁴ + ... + a0``.

    Parameters
    ----------
    space : ParameterSpace
        The preset (with overrides) or complete parameter set; every other
        settable name keeps its value in ``space`` and tied names follow.
    axis : Axis
        The path: ``axis.name`` must be a settable name of ``space``;
        ``start`` and ``stop`` bound it (SI unit of the parameter; any width,
        e.g. ``1e-100`` to ``1e100``).  ``log`` only selects where stability is
        sampled between candidates (geometric instead of arithmetic
        midpoints) and the spacing of the numeric fallback's grid; ``num`` is
        ignored.

    Returns
    -------
    CrossingResult
        ``stable_at_start`` (verdict just above ``start``) and the crossings
        with their direction (``"destabilizing"``: stable before, unstable
        after, in the direction of increasing parameter), in increasing order,
        ``method``, ``undecided_ranges`` and ``exhaustive``.

    Raises
    ------
    ParameterError
        If ``axis.name`` is tied or not a settable name of ``space``, or the
        parameters are invalid at ``start``.

    Notes
    -----
    When the closed-form quartic is rational in the parameter and the silent
    motion is trivial along the whole path (eq. 49), the candidates are the
    real roots of the exact numerators of ``a0``, ``a4``, of the Hurwitz
    determinant ``H3 = a1 (a2 a3 - a1 a4) - a0 a3²`` and of the common
    denominator, isolated exactly on the whole range; the result is complete
    and exact (crossing values to ~1e-15 relative).  Sub-ranges whose
    parameters are invalid are reported in ``undecided_ranges``.  Otherwise
    the numeric linearization is evaluated on an 801-point grid along the
    path, sign changes of the certified verdict are bracketed and the
    crossing is polished with Brent's method on the largest real part
    (``exhaustive=False``).
    """
    from ..results import CrossingResult

    space.check_axis(axis.name)
    space.resolve({axis.name: axis.start})
    qn = quartic_numerators(space, (axis.name,))
    if qn is not None:
        start, found, undecided = exact_crossings(qn, axis.start, axis.stop, axis.log, _valid_fn(space, axis.name))
        method, exhaustive = "exact (isolated real roots of the Hurwitz polynomials of the closed form)", True
    else:
        start, found, undecided = _numeric(space, axis)
        method, exhaustive = "numeric linearization (certified verdicts on an 801-point grid + Brent)", False
    return CrossingResult(parameter=axis.name, start=axis.start, stop=axis.stop, log=axis.log,
                          stable_at_start=start, crossings=tuple(found), method=method, space=space,
                          undecided_ranges=tuple(undecided), exhaustive=exhaustive)


def _omega_batchable(space: ParameterSpace) -> bool:
    if any("Omega" in names_in(e) for e in space.tied.values()):
        return False
    return space.resolve({}).trivial_silent_motion()


def critical_speeds(space: ParameterSpace, lo: float = 1.0, hi: float = 1e5) -> object:
    """All onsets and re-stabilisations of squeal along the spin rate Ω in ``(lo, hi)`` [rad/s].

    Uses the certified compiled Laurent-polynomial kernel when the silent
    motion is trivial (eq. 49) and no tied name depends on ``Omega`` (sets it
    cannot certify are recomputed by exact root isolation; at most 16
    crossings reported), otherwise :func:`crossings` along a logarithmic Ω
    axis.  The smallest destabilizing Ω is the critical speed ``Omega_crit``
    of the paper's Fig. 3.  Any range ``0 < lo < hi`` is handled (split into
    sub-ranges internally).

    Parameters
    ----------
    space : ParameterSpace
        The preset (with overrides) or complete parameter set; ``Omega`` must
        be one of its settable names (not tied).
    lo, hi : float, optional
        The Ω range [rad/s], ``0 < lo < hi`` (default ``1.0`` to ``1e5``).

    Returns
    -------
    CriticalSpeedResult
        Crossings along ``Omega`` (``log=True``); its ``Omega_crit`` is the
        first destabilizing one, or ``None``; ``Omega_crit_certain`` and
        ``undecided_ranges`` state what is established.

    Raises
    ------
    ParameterError
        If ``Omega`` is tied or not settable in ``space``, the range is empty,
        reversed or not positive, or the parameters are invalid.
    """
    from ..results import CriticalSpeedResult

    axis = Axis("Omega", lo, hi, 2, True)
    space.check_axis("Omega")
    if _omega_batchable(space):
        from .equilibrium import parameter_vector

        p = np.array([parameter_vector(space.resolve({}))])
        roots, dirs, counts, start, status = critical_speeds_batch(p, lo, hi, max_crossings=16, return_status=True)
        found = tuple((float(roots[0, k]), "stabilizing" if dirs[0, k] > 0 else "destabilizing")
                      for k in range(min(int(counts[0]), 16)))
        undecided: tuple[tuple[float, float], ...] = ()
        if status[0] != 0:
            _, _, und = exact_omega_crossings(p[0], lo, hi)
            undecided = tuple(und) or ((lo, hi),)
        return CriticalSpeedResult(parameter="Omega", start=lo, stop=hi, log=True, stable_at_start=bool(start[0]),
                                   crossings=found, method="exact (certified compiled Laurent-polynomial Hurwitz "
                                   "kernel, exact rational fallback)", space=space, undecided_ranges=undecided)
    r = crossings(space, axis)
    return CriticalSpeedResult(parameter="Omega", start=lo, stop=hi, log=True, stable_at_start=r.stable_at_start,
                               crossings=r.crossings, method=r.method, space=space,
                               undecided_ranges=r.undecided_ranges, exhaustive=r.exhaustive)


def critical_speeds_many(space: ParameterSpace, changes: dict[str, np.ndarray], lo: float = 1.0, hi: float = 1e5,
                         max_crossings: int = 8) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Batched critical speeds over arrays of settable values (trivial silent motion required).

    Each of the ``n`` points resolves ``space`` with the values of
    ``changes`` at that index, then the certified compiled kernel of
    :func:`~brakesqueal.analysis.kernels.critical_speeds_batch` finds every
    stability change along Ω in ``(lo, hi)`` (exact fallback per set).  Tied
    names are evaluated with the space's own value of ``Omega`` (use
    :func:`critical_speeds` when one depends on ``Omega``).

    Parameters
    ----------
    space : ParameterSpace
        The preset (with overrides) or complete parameter set.
    changes : dict of str to array_like
        Settable names of ``space`` → values in their SI units; scalars and
        1-D arrays, broadcast to a common length ``n`` (an empty dict gives
        one point: ``space`` itself).
    lo, hi : float, optional
        The Ω range [rad/s], ``0 < lo < hi`` (default ``1.0`` to ``1e5``).
    max_crossings : int, optional
        Columns of the output arrays (default 8); further crossings are only
        counted.

    Returns
    -------
    crossings : ndarray, shape (n, max_crossings)
        Ω values [rad/s] where stability changes, ascending, NaN-padded.
    directions : ndarray of int8, shape (n, max_crossings)
        ``-1`` destabilizing (stable below, unstable above), ``+1`` stabilizing.
    counts : ndarray of int64, shape (n,)
        Number of crossings found (may exceed ``max_crossings``).
    stable_at_start : ndarray of bool, shape (n,)
        Verdict just above ``lo``.

    Raises
    ------
    ParameterError
        If a name is tied or not settable, a point has invalid parameters, or
        its silent motion is not trivial (``mu1 h10 != mu2 h20``, eq. 49).
    """
    from .equilibrium import parameter_vector

    Axis("Omega", lo, hi, 2, True)
    names = list(changes)
    for n in names:
        space.check_axis(n)
    n_pts = np.broadcast(*changes.values()).size if changes else 1
    cols = {k: np.broadcast_to(np.asarray(v, dtype=float), (n_pts,)) for k, v in changes.items()}
    P = np.empty((n_pts, 17))
    for i in range(n_pts):
        prm = space.resolve({k: float(v[i]) for k, v in cols.items()})
        if not prm.trivial_silent_motion():
            raise ParameterError("critical_speeds_many needs a trivial silent motion (mu1*h10 = mu2*h20, eq. 49)")
        P[i] = parameter_vector(prm)
    return critical_speeds_batch(P, lo, hi, max_crossings)  # type: ignore[return-value]
