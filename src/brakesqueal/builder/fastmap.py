"""Eigenvalue-free stability classification for maps of built models.

For a map over two parameters ``x`` and ``y`` the coefficients of the
characteristic polynomial ``p(λ) = det(λ² M + λ D + K)`` of a built model (at a
trivial silent motion) are polynomials in ``t_x`` and ``t_y``, where ``t`` is the
parameter or its reciprocal (the matrix entries are polynomial in masses,
stiffnesses and friction coefficients, and in compliances ``1/k_ip`` and
``1/Omega``).  The degrees are detected numerically; the coefficients are
sampled on a small Chebyshev tensor grid (eigenvalues of the state matrix,
``numpy.poly``), interpolated, and evaluated per point; the verdict is the
*certified* Routh test of :func:`~brakesqueal.analysis.robust.routh_verdicts`
with coefficient error radii estimated from the interpolation: the
interpolant is compared with directly computed coefficients at validation
points, and the radius is 100 times the largest deviation plus a floor.
Points whose verdict cannot be certified within these radii are returned as
"to do" and computed with the eigenvalue route (with its own error bound).

When no polynomial structure is found (degree > ``MAX_DEGREE``),
:func:`classify` returns ``None`` and callers use batched eigenvalues.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..analysis.robust import routh_verdicts

__all__ = ["classify", "MAX_DEGREE"]

MAX_DEGREE = 24
_TOL = 1e-9


def _cheb_nodes(k: int) -> np.ndarray:
    return np.cos(np.pi * (np.arange(k) + 0.5) / k)[::-1]


def _charpoly(mats: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]],
              xs: np.ndarray, ys: np.ndarray, scale: float) -> np.ndarray:
    """Scaled characteristic-polynomial coefficients (highest power first) at the points (xs, ys)."""
    M, D, K = mats(xs, ys)
    n = M.shape[-1]
    Minv = np.linalg.inv(M)
    A = np.zeros((xs.size, 2 * n, 2 * n))
    A[:, :n, n:] = np.eye(n)
    A[:, n:, :n] = -Minv @ K
    A[:, n:, n:] = -Minv @ D
    lam = np.linalg.eigvals(A) / scale
    c = np.array([np.poly(row).real for row in lam])  # monic in μ = λ / scale
    detM = np.linalg.det(M)
    return c * (detM / np.abs(detM).max())[:, None]  # det(λ²M + λD + K) / const: polynomial in the parameters


def _degree(f: Callable[[np.ndarray], np.ndarray]) -> int | None:
    """Smallest degree d such that the coefficients sampled along [-1, 1] are polynomials of degree d."""
    u = _cheb_nodes(MAX_DEGREE + 4)
    vals = f(u)
    scale = np.abs(vals).max(axis=0) + 1e-300
    for d in range(0, MAX_DEGREE + 1):
        V = np.polynomial.chebyshev.chebvander(u, d)
        coef, *_ = np.linalg.lstsq(V, vals, rcond=None)
        if np.all(np.abs(V @ coef - vals) <= _TOL * scale):
            return d
    return None


def classify(mats: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]],
             xv: np.ndarray, yv: np.ndarray, *, x_log: bool, y_log: bool) -> np.ndarray | None:
    """Certified verdict codes on the grid ``yv × xv`` (shape ``(len(yv), len(xv))``), or ``None``.

    Codes: 0 unstable, 1 stable, 2 uncertain within the estimated coefficient
    errors (callers compute those points with eigenvalues).

    Parameters
    ----------
    mats : callable
        ``mats(x, y) -> (M, D, K)`` for 1-D arrays of points (batched ``n × n`` matrices).
    xv, yv : ndarray
        Axis values (all points must have a trivial silent motion).
    x_log, y_log : bool
        Unused hints kept for symmetry with the axis definitions (the reciprocal
        transform is chosen from the data).

    Returns
    -------
    ndarray of uint8, or None
        ``None`` when the coefficients are not polynomial of degree ≤ :data:`MAX_DEGREE`
        in the parameter or its reciprocal.
    """
    def transforms(v: np.ndarray) -> list[tuple[Callable[[np.ndarray], np.ndarray], Callable[[np.ndarray], np.ndarray],
                                               np.ndarray]]:
        lo, hi = v.min(), v.max()
        out = [(lambda u, lo=lo, hi=hi: lo + (u + 1) * (hi - lo) / 2, lambda w, lo=lo, hi=hi: 2 * (w - lo) / (hi - lo) - 1,
                v)]  # fmt: skip
        if lo > 0:
            a, b = 1 / hi, 1 / lo
            out.append((lambda u, a=a, b=b: 1 / (a + (u + 1) * (b - a) / 2),
                        lambda w, a=a, b=b: 2 * (1 / w - a) / (b - a) - 1, v))  # fmt: skip
        return out

    xc, yc = np.array([np.median(xv)]), np.array([np.median(yv)])
    M, D, K = mats(xc, yc)
    n = M.shape[-1]
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -np.linalg.solve(M[0], K[0])
    A[n:, n:] = -np.linalg.solve(M[0], D[0])
    scale = float(np.exp(np.mean(np.log(np.abs(np.linalg.eigvals(A)) + 1e-300))))
    chosen = []
    for axis, v in ((0, xv), (1, yv)):
        best = None
        for fwd, inv, _ in transforms(v):
            if axis == 0:
                f = lambda u: _charpoly(mats, fwd(u), np.full(u.size, yc[0]), scale)  # noqa: E731
            else:
                f = lambda u: _charpoly(mats, np.full(u.size, xc[0]), fwd(u), scale)  # noqa: E731
            d = _degree(f)
            if d is not None and (best is None or d < best[0]):
                best = (d, fwd, inv)
        if best is None:
            return None
        chosen.append(best)
    (dx, fx, ix), (dy, fy, iy) = chosen
    ux, uy = _cheb_nodes(dx + 1), _cheb_nodes(dy + 1)
    UX, UY = np.meshgrid(ux, uy)
    C = _charpoly(mats, fx(UX.ravel()), fy(UY.ravel()), scale)  # ((dy+1)(dx+1), m)
    m = C.shape[1]
    Vx = np.polynomial.chebyshev.chebvander(ux, dx)
    Vy = np.polynomial.chebyshev.chebvander(uy, dy)
    vals = C.reshape(dy + 1, dx + 1, m)
    # Chebyshev coefficients G[j, ly, lx] with vals[iy, ix, j] = sum Vy[iy, ly] Vx[ix, lx] G[j, ly, lx]
    G = np.einsum("ab,bcj,dc->jad", np.linalg.inv(Vy), vals, np.linalg.inv(Vx))
    radius = _interpolation_radius(mats, G, fx, fy, dx, dy, scale)
    Tx = np.polynomial.chebyshev.chebvander(ix(xv), dx)
    Ty = np.polynomial.chebyshev.chebvander(iy(yv), dy)
    out = np.empty((yv.size, xv.size), dtype=np.uint8)
    for r in range(yv.size):
        B = np.einsum("jab,a->jb", G, Ty[r])  # (m, dx+1)
        coef = (Tx @ B.T)[:, ::-1]  # ascending in μ
        out[r] = routh_verdicts(coef, np.broadcast_to(radius[::-1], coef.shape))
    return out


def _interpolation_radius(mats: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]],
                          G: np.ndarray, fx: Callable[[np.ndarray], np.ndarray], fy: Callable[[np.ndarray], np.ndarray],
                          dx: int, dy: int, scale: float, n: int = 24) -> np.ndarray:
    """Estimated absolute error of every interpolated coefficient (highest power first).

    Deviation of the interpolant from directly computed coefficients at
    ``n`` pseudo-random validation points of ``[-1, 1]²``, times 100, plus
    ``1e-12`` of the coefficient's largest magnitude (the direct values come
    from eigenvalues and carry their own rounding).
    """
    u = np.random.default_rng(12345).uniform(-1, 1, (2, n))
    direct = _charpoly(mats, fx(u[0]), fy(u[1]), scale)
    Tx = np.polynomial.chebyshev.chebvander(u[0], dx)
    Ty = np.polynomial.chebyshev.chebvander(u[1], dy)
    interp = np.einsum("jab,na,nb->nj", G, Ty, Tx)
    dev = np.max(np.abs(interp - direct), axis=0)
    mag = np.max(np.abs(direct), axis=0)
    return 100.0 * dev + 1e-12 * np.max(mag) + 1e-13 * mag
