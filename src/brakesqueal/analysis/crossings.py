r"""Exact stability changes along a 1-D path and critical speeds.

Stability changes only where the characteristic quartic has a root at 0
(``a0 = 0``) or a pair on the imaginary axis (``H3 = 0``); both are rational
in the path parameter for the closed forms, so the candidates are the real
roots of polynomials, isolated exactly (:func:`~.kernels.real_roots`), and
stability is decided between consecutive candidates by Liénard–Chipart.
Reading a grid is never used for the closed-form path; the numeric fallback
(non-trivial silent motion) brackets sign changes of the verdict on a fine
grid and polishes with Brent's method on the largest real part.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.polynomial import polynomial as npoly

from ..errors import ParameterError
from ..expressions import names_in
from .kernels import critical_speeds_batch, hurwitz_stable, path_polynomials, real_roots
from .maps import Axis
from .space import ParameterSpace

__all__ = ["crossings", "critical_speeds", "critical_speeds_many"]


def _hurwitz_poly(A: list[np.ndarray]) -> np.ndarray:
    a0, a1, a2, a3, a4 = A
    return npoly.polysub(npoly.polymul(a1, npoly.polysub(npoly.polymul(a3, a2), npoly.polymul(a4, a1))),
                         npoly.polymul(npoly.polymul(a3, a3), a0))


def _stable_poly(A: list[np.ndarray], P: np.ndarray, t: float) -> bool:
    vals = [npoly.polyval(t, a) for a in A]
    return bool(hurwitz_stable(*vals)) and bool(np.sign(vals[4]) * npoly.polyval(t, P) > 0)


def _exact(space: ParameterSpace, axis: Axis) -> tuple[bool, list[tuple[float, str]]] | None:
    res = path_polynomials(space, axis.name, axis.start > 0)
    if res is None:
        return None
    polys, _ = res
    ref = axis.ref
    A = [np.asarray(a, dtype=float) * ref ** np.arange(a.size) for a in polys]
    mx = max(float(np.max(np.abs(a))) for a in A)
    A = [a / mx for a in A]
    P = _hurwitz_poly(A)
    P = P / max(float(np.max(np.abs(P))), 1e-300)
    lo, hi = axis.start / ref, axis.stop / ref
    cand = list(real_roots(P, lo, hi))
    for a in A:
        cand.extend(real_roots(a, lo, hi))
    cand = sorted(set(cand))
    out: list[tuple[float, str]] = []
    prev = _stable_poly(A, P, lo)
    start = prev
    for q, c in enumerate(cand):
        b = cand[q + 1] if q + 1 < len(cand) else hi
        if b <= c:
            continue
        mid = math.sqrt(c * b) if axis.log else 0.5 * (c + b)
        st = _stable_poly(A, P, mid)
        if st != prev:
            out.append((c * ref, "stabilizing" if st else "destabilizing"))
            prev = st
    return start, out


def _numeric(space: ParameterSpace, axis: Axis, n: int = 801) -> tuple[bool, list[tuple[float, str]]]:
    from scipy.optimize import brentq

    from .maps import _numeric_point, _roots_summary

    grid = Axis(axis.name, axis.start, axis.stop, n, axis.log).values()

    def verdict(v: float) -> tuple[bool, float]:
        code, c = _numeric_point(space, {axis.name: float(v)})
        if c is None:
            return False, math.nan
        return bool(hurwitz_stable(*c)), float(_roots_summary(c)[0][0])

    vs = [verdict(v) for v in grid]
    out: list[tuple[float, str]] = []
    for (a, (sa, ma)), (b, (sb, mb)) in zip(zip(grid, vs), zip(grid[1:], vs[1:])):
        if sa == sb:
            continue
        x = a
        if math.isfinite(ma) and math.isfinite(mb) and ma * mb < 0:
            x = brentq(lambda v: verdict(v)[1], a, b, xtol=1e-300, rtol=1e-15, maxiter=200)
        out.append((x, "stabilizing" if sb else "destabilizing"))
    return vs[0][0], out


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
        ``start`` and ``stop`` bound it (SI unit of the parameter).  ``log``
        only selects where stability is sampled between candidates (geometric
        instead of arithmetic midpoints) and the spacing of the numeric
        fallback's grid; ``num`` is ignored.

    Returns
    -------
    CrossingResult
        ``stable_at_start`` (verdict at ``start``) and the crossings with their
        direction (``"destabilizing"``: stable before, unstable after, in the
        direction of increasing parameter), in increasing order, and ``method``.

    Raises
    ------
    ParameterError
        If ``axis.name`` is tied or not a settable name of ``space``, or the
        parameters are invalid at ``start``.

    Notes
    -----
    When the closed-form quartic is rational in the parameter and the silent
    motion is trivial along the whole path (eq. 49), the candidates are the
    real roots of ``a0`` (a root ``λ = 0``) and of the Hurwitz determinant
    ``H3 = a1 (a2 a3 - a1 a4) - a0 a3²`` (a pair ``λ = ±iω``), isolated
    exactly; the result is then exact to rounding.  Otherwise the numeric
    linearization is evaluated on an 801-point grid along the path, sign
    changes of the verdict are bracketed and the crossing is polished with
    Brent's method on the largest real part; two crossings closer together
    than the grid spacing may then be missed.
    """
    from ..results import CrossingResult

    space.check_axis(axis.name)
    space.resolve({axis.name: axis.start})
    res = _exact(space, axis)
    method = "exact (roots of the Hurwitz polynomials of the closed form)"
    if res is None:
        res = _numeric(space, axis)
        method = "numeric linearization (grid bracketing + Brent on max Re λ)"
    start, found = res
    return CrossingResult(parameter=axis.name, start=axis.start, stop=axis.stop, log=axis.log,
                          stable_at_start=start, crossings=tuple(found), method=method, space=space)


def _omega_batchable(space: ParameterSpace) -> bool:
    if any("Omega" in names_in(e) for e in space.tied.values()):
        return False
    return space.resolve({}).trivial_silent_motion()


def critical_speeds(space: ParameterSpace, lo: float = 1.0, hi: float = 1e5) -> object:
    """All onsets and re-stabilisations of squeal along the spin rate Ω in ``(lo, hi)`` [rad/s].

    Uses the compiled Laurent-polynomial kernel when the silent motion is
    trivial (eq. 49) and no tied name depends on ``Omega`` (relative accuracy
    ~1e-12, at most 16 crossings reported), otherwise :func:`crossings` along
    a logarithmic Ω axis.  The smallest destabilizing Ω is the critical speed
    ``Omega_crit`` of the paper's Fig. 3.

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
        first destabilizing one, or ``None``.

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
        roots, dirs, counts, start = critical_speeds_batch(p, lo, hi, max_crossings=16)
        found = tuple((float(roots[0, k]), "stabilizing" if dirs[0, k] > 0 else "destabilizing")
                      for k in range(min(int(counts[0]), 16)))
        return CriticalSpeedResult(parameter="Omega", start=lo, stop=hi, log=True, stable_at_start=bool(start[0]),
                                   crossings=found, method="exact (compiled Laurent-polynomial Hurwitz kernel)",
                                   space=space)
    r = crossings(space, axis)
    return CriticalSpeedResult(parameter="Omega", start=lo, stop=hi, log=True, stable_at_start=r.stable_at_start,
                               crossings=r.crossings, method=r.method, space=space)


def critical_speeds_many(space: ParameterSpace, changes: dict[str, np.ndarray], lo: float = 1.0, hi: float = 1e5,
                         max_crossings: int = 8) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Batched critical speeds over arrays of settable values (trivial silent motion required).

    Each of the ``n`` points resolves ``space`` with the values of
    ``changes`` at that index, then the compiled kernel of
    :func:`~brakesqueal.analysis.kernels.critical_speeds_batch` finds every
    stability change along Ω in ``(lo, hi)``.  Tied names are evaluated with
    the space's own value of ``Omega`` (use :func:`critical_speeds` when one
    depends on ``Omega``).

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
    return critical_speeds_batch(P, lo, hi, max_crossings)

