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

    Returns
    -------
    CrossingResult
        ``stable_at_start`` and the crossings with their direction
        (``"destabilizing"``: stable before, unstable after, in the direction of
        increasing parameter).
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
    trivial (relative accuracy ~1e-12), otherwise :func:`crossings` along Ω.
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

    Returns ``(crossings, directions, counts, stable_at_start)`` as
    :func:`~.kernels.critical_speeds_batch`; rows with a non-trivial silent
    motion or invalid parameters raise ParameterError.
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

