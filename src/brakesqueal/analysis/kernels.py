r"""Certified stability criteria of 2-DOF models, generated from the closed forms and compiled.

The characteristic polynomial of eq. (47) for a 2-DOF model is the quartic

.. math:: \det(\lambda^2 \bar M + \lambda \bar D + \bar K)
          = a_4 \lambda^4 + a_3 \lambda^3 + a_2 \lambda^2 + a_1 \lambda + a_0 .

All roots have negative real parts iff (Liénard–Chipart / Hurwitz) every
``s a_i > 0`` and ``s H3 > 0`` with ``s = sign(a4)`` and
``H3 = a3 a2 a1 - a4 a1^2 - a3^2 a0`` (the third Hurwitz determinant).  The
test is invariant under multiplying all ``a_i`` by one non-zero number — so
a common denominator of any sign may be dropped *per point* — and under
``λ -> σλ`` (``a_i -> a_i σ^i``).  Stability can only change where ``a0 = 0``,
``H3 = 0`` or ``a4 = 0`` (Orlando's formula).

Every floating-point verdict made here is *certified*: values carry a
rigorous bound of their rounding error and a sign is only used when it
exceeds the bound; otherwise the point is reported *uncertain* and the caller
recomputes it by a robust route (:mod:`.robust`).

The kernels themselves are generated once per model (or per parameter space
and axes) by the model's :class:`~brakesqueal.codegen.engine.Engine` from its
closed form (:mod:`brakesqueal.symbolic.stability_forms`) and kept in the on-disk
cache; this module only *runs* them:

* :func:`kernel_eigen`, :func:`run_classify` — the
  grid kernels' verdicts and roots (:meth:`Engine.grid_kernel
  <brakesqueal.codegen.engine.Engine.grid_kernel>`: the exact numerators of the
  quartic as polynomials in one *inner* axis, rows evaluated in
  exponent-scaled floating point with an error bound, the inner loop compiled
  with numba returning 0 (unstable), 1 (stable) or 2 (uncertain));
* :func:`trivial_entries` — ``Mbar, Dbar, Kbar`` from a parameter vector with
  a rigorous rounding bound per entry (generated, compiled);
* :func:`omega_entries` — ``Mbar, Dbar, Kbar`` are Laurent polynomials in Ω,
  so ``Ω^6 H3`` is a polynomial in Ω; :func:`~.crossings.critical_speeds_batch`
  isolates its real roots with certified Descartes bisection in compiled code
  (:func:`~._compiled.critical_batch`) and recomputes exactly the sets that
  cannot be certified;
* :func:`charpoly_verdicts` — the exact characteristic polynomial of a zero
  state of any size on a grid (:meth:`Engine.charpoly_table
  <brakesqueal.codegen.engine.Engine.charpoly_table>`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ..codegen.stability import CharpolyTable, GridKernel, MapKernel, inner_exponent, kernel_segments

if TYPE_CHECKING:
    from ..codegen.engine import Engine

__all__ = [
    "quartic_coefficients", "hurwitz_h3", "hurwitz_stable", "GridKernel", "MapKernel", "CharpolyTable",
    "real_roots", "trivial_entries", "omega_entries", "omega_subranges",
    "inner_exponent", "kernel_segments", "run_classify", "kernel_scaling", "kernel_eigen", "charpoly_verdicts",
    "CHARPOLY_ACCURACY", "CHARPOLY_ROUTE", "CHARPOLY_BLOCK",
]

_U = 2.0 ** -53


def quartic_coefficients(M: Any, D: Any, K: Any) -> tuple[Any, Any, Any, Any, Any]:
    """``(a0, a1, a2, a3, a4)`` of ``det(λ²M + λD + K)`` for 2×2 matrices (last two axes).

    Works for NumPy arrays of shape ``(..., 2, 2)`` and SymPy matrices.
    """
    def e(X: Any, i: int, j: int) -> Any:
        return X[i, j] if hasattr(X, "shape") and len(getattr(X, "shape", ())) == 2 else X[..., i, j]

    m11, m12, m21, m22 = e(M, 0, 0), e(M, 0, 1), e(M, 1, 0), e(M, 1, 1)
    d11, d12, d21, d22 = e(D, 0, 0), e(D, 0, 1), e(D, 1, 0), e(D, 1, 1)
    k11, k12, k21, k22 = e(K, 0, 0), e(K, 0, 1), e(K, 1, 0), e(K, 1, 1)
    a4 = m11 * m22 - m12 * m21
    a3 = m11 * d22 + d11 * m22 - m12 * d21 - d12 * m21
    a2 = m11 * k22 + d11 * d22 + k11 * m22 - m12 * k21 - d12 * d21 - k12 * m21
    a1 = d11 * k22 + k11 * d22 - d12 * k21 - k12 * d21
    a0 = k11 * k22 - k12 * k21
    return a0, a1, a2, a3, a4


def hurwitz_h3(a0: Any, a1: Any, a2: Any, a3: Any, a4: Any) -> Any:
    """Third Hurwitz determinant ``a3 a2 a1 - a4 a1² - a3² a0`` of the quartic."""
    return a1 * (a3 * a2 - a4 * a1) - a3 * a3 * a0


def hurwitz_stable(a0: Any, a1: Any, a2: Any, a3: Any, a4: Any) -> Any:
    """Liénard–Chipart verdict (bool array) in plain floating point, *not certified*.

    Kept for quick checks on well-scaled coefficients; the analysis routes use
    the certified tests of :mod:`.robust` (:func:`~.robust.routh_verdicts`).
    """
    s = np.sign(a4)
    a0, a1, a2, a3, a4 = (np.asarray(a) * s for a in (a0, a1, a2, a3, a4))
    return (a0 > 0) & (a1 > 0) & (a2 > 0) & (a3 > 0) & (a4 > 0) & (hurwitz_h3(a0, a1, a2, a3, a4) > 0)


def kernel_scaling(kern: GridKernel | MapKernel | None, inner_values: np.ndarray) -> tuple[int, np.ndarray] | None:
    """Inner-axis scaling ``(e, t)`` if the kernel's Horner evaluation stays in range for these values.

    Parameters
    ----------
    kern : GridKernel or MapKernel or None
        The kernel (``None`` gives ``None``).
    inner_values : ndarray
        Values of the kernel's inner axis.

    Returns
    -------
    tuple or None
        ``(e, t)`` with ``t = inner_values / 2^e`` (see :func:`inner_exponent`),
        or ``None`` when ``|t|^degree`` could reach ``2^300`` (the kernel then
        does not apply; no overflow, no NaN in the compiled loop).
    """
    if kern is None:
        return None
    e = inner_exponent(inner_values)
    t = np.ldexp(np.asarray(inner_values, dtype=float), -e)
    deg = max(kern.degrees)
    tmax = float(np.max(np.abs(t))) if t.size else 0.0
    if not (np.all(np.isfinite(t)) and (tmax <= 1 or deg * math.log2(tmax) < 300)):
        return None
    return e, t


def run_classify(kern: GridKernel | MapKernel, C: np.ndarray, EC: np.ndarray, t: np.ndarray,
                 out: np.ndarray | None = None) -> np.ndarray:
    """Call the compiled classifier on row tables ``C, EC`` and inner values ``t`` (codes 0/1/2)."""
    t = np.ascontiguousarray(t, dtype=float)
    if out is None:
        out = np.empty((C.shape[0], t.size), dtype=np.uint8)
    seg, T = kernel_segments(t)
    kern.classify(C, EC, t, seg, T, out)
    return out


def kernel_eigen(kern: GridKernel | MapKernel, C: np.ndarray, t: np.ndarray, lam_e: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Max Re λ and its frequency at every point of a kernel's rows (compiled roots of the quartic).

    The quartic's coefficients come from the same row tables as the verdict
    (:meth:`GridKernel.row_tables`); its roots from Newton's method on the
    factorization into two real quadratics, warm-started from the neighbouring
    points (:func:`~._compiled.quartic_top_grid`).

    Parameters
    ----------
    kern : GridKernel or MapKernel
        The kernel.
    C : ndarray, shape (rows, ncol)
        Row tables.
    t : ndarray
        Scaled inner values.
    lam_e : ndarray of int64
        Per row, the exponent of its balancing (``λ = 2^lam_e ν``).

    Returns
    -------
    max_real, frequency : ndarray, shape (rows, t.size)
        ``max Re λ`` [1/s] and ``|Im λ| / 2π`` [Hz] of that root.
    ok : ndarray of uint8
        0 where the roots were not found cleanly (NaN there; the caller recomputes those points).
    """
    from ._compiled import PARALLEL_MIN, quartic_top_grid, quartic_top_grid_chunks

    t = np.ascontiguousarray(t, dtype=float)
    rows = C.shape[0]
    A = np.empty((5, rows, t.size))
    kern.coefficients(C, t, A)
    mr = np.empty((rows, t.size))
    fr = np.empty((rows, t.size))
    ok = np.empty((rows, t.size), dtype=np.uint8)
    le = np.ascontiguousarray(lam_e, dtype=np.int64)
    with np.errstate(all="ignore"):
        try:
            if rows * t.size >= PARALLEL_MIN and rows > CHARPOLY_BLOCK:
                # blocks of rows in parallel, each warm-starting itself (results independent of the thread count)
                quartic_top_grid_chunks(A, le, mr, fr, ok, CHARPOLY_BLOCK)
            else:
                quartic_top_grid(A, le, mr, fr, ok)
        except ZeroDivisionError:
            # numba's complex division raises on a zero divisor (coefficients at the magnitude limits, e.g.
            # Omega = 1e-99): no root is taken from this block, the caller recomputes every point
            mr[:], fr[:], ok[:] = np.nan, np.nan, 0
    return mr, fr, ok


# ---------------------------------------------------------------- real roots (compiled, floating point)


def real_roots(coeffs: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Real roots of the polynomial ``Σ coeffs[k] x^k`` in the open interval ``(lo, hi)`` (floating point).

    Derivative cascade (the roots of ``p'`` split the interval into monotone
    pieces), each root polished by safeguarded Newton.  Not certified; the
    analysis routes use :func:`~.robust.isolate_real_roots` (exact) or the
    certified compiled isolation.
    """
    from ._compiled import real_roots as _rr

    c = np.ascontiguousarray(coeffs, dtype=float)
    out = np.empty(max(c.size, 1))
    n = _rr(c, float(lo), float(hi), out)
    return out[:n].copy()


# ---------------------------------------------------------------- closed-form entries, Laurent coefficients in Omega
def trivial_entries(engine: Engine, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``Mbar, Dbar, Kbar`` (trivial silent motion, closed form) with rigorous rounding bounds.

    Parameters
    ----------
    engine : Engine
        The model's engine; it needs a closed form (:attr:`Capabilities.closed_form
        <brakesqueal.codegen.engine.Capabilities.closed_form>`).
    P : ndarray, shape (n, n_parameters)
        Parameter vectors in the model's packing order (``spec.parameters``,
        compliances ``c = 1/k_ip`` for tangential stiffnesses, as
        :meth:`Parameters.vector <brakesqueal.model.parameters.Parameters.vector>`).

    Returns
    -------
    E, R : ndarray, shape (n, 12)
        Entries of ``M, D, K`` (row-major) and bounds on their rounding errors
        (exact for the given parameter vector).
    """
    from ._pure import SMALL

    P = np.ascontiguousarray(np.atleast_2d(P), dtype=float)
    E = np.empty((P.shape[0], 12))
    R = np.empty((P.shape[0], 12))
    with np.errstate(all="ignore"):
        # a few points (a command's one point): the same source as plain Python, no numba import
        engine.entries_kernel(plain=P.shape[0] <= SMALL).entries_batch(P, E, R)
    return E, R


def omega_entries(engine: Engine, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Laurent coefficients in Ω of the 12 entries of ``Mbar, Dbar, Kbar``, with rounding bounds.

    Parameters
    ----------
    engine : Engine
        The model's engine (:attr:`Capabilities.omega_kernel <brakesqueal.codegen.engine.Capabilities.omega_kernel>`).
    P : ndarray, shape (n, n_parameters)
        Parameter vectors in the model's packing order (Ω ignored).

    Returns
    -------
    E, R : ndarray, shape (n, 12, 4)
        ``entry = Σ_k E[.., e, k] Ω^(k-1)`` and the rounding bounds.
    """
    mod = engine.omega_kernel()
    if mod is None:
        raise NotImplementedError(f"model '{engine.spec.name}' has no Laurent form in its spin")
    P = np.ascontiguousarray(np.atleast_2d(P), dtype=float)
    V = np.empty((P.shape[0], 48))
    R = np.empty((P.shape[0], 48))
    with np.errstate(all="ignore"):
        mod.entries_batch(P, V, R)
    return V.reshape(-1, 12, 4), R.reshape(-1, 12, 4)


def omega_subranges(lo: float, hi: float, decades: float = 6.0) -> np.ndarray:
    """Sub-range limits ``lo = b_0 < b_1 < … < b_J = hi`` with internal limits powers of two, ratio ≲ ``10^decades``."""
    if not (0 < lo < hi and math.isfinite(hi)):
        from ..errors import ParameterError

        raise ParameterError(f"the Omega range needs 0 < START < STOP (finite); got {lo!r}:{hi!r}")
    step = max(1, int(decades * math.log2(10)))
    e0, e1 = math.floor(math.log2(lo)) + 1, math.ceil(math.log2(hi)) - 1
    inner = [2.0 ** e for e in range(e0 + step // 2, e1, step)] if e1 - e0 > step else []
    pts = [lo] + [b for b in inner if lo < b < hi] + [hi]
    return np.array(pts, dtype=float)


# ---------------------------------------------------------------- n-DOF: the exact characteristic polynomial on a grid
#: Relative accuracy of every root (Gerschgorin disk radius / |root|) that the characteristic-polynomial route
#: requires before it reports ``max_real`` and the frequency (otherwise the point goes to the eigenvalue route).

CHARPOLY_ACCURACY = 1e-9
#: Rows per block of the characteristic-polynomial kernel (blocks run in parallel; each warm-starts itself).

CHARPOLY_BLOCK = 64
#: The route's name in results' ``method`` (ASCII: NetCDF3 attributes).

CHARPOLY_ROUTE = ("per point, compiled: certified roots of the exact characteristic polynomial "
                  "det(lam^2 M + lam D + K) (Weierstrass/Gerschgorin inclusion disks, warm-started along rows); "
                  "certified eigenvalue verdicts where the disks do not decide")



def charpoly_verdicts(table: CharpolyTable, outer_values: np.ndarray, inner_values: np.ndarray,
                      valid: np.ndarray | None = None, *, eigen: bool = True
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Certified verdicts, ``max Re λ`` and frequency on a grid from the exact characteristic polynomial.

    Parameters
    ----------
    table : CharpolyTable
        From :func:`charpoly_table`.
    outer_values, inner_values : ndarray
        Grid values of ``table.outer`` and ``table.inner``.
    valid : ndarray of bool, shape (outer, inner), optional
        Points to compute (default all).
    eigen : bool
        Require every root to be accurate to :data:`CHARPOLY_ACCURACY`
        (relative) before a point is reported (for ``max_real`` and the
        frequency); otherwise the verdict alone is certified.

    Returns
    -------
    codes, max_real, frequency : ndarray, shape (outer, inner)
        :data:`~.robust.STABLE`, :data:`~.robust.UNSTABLE` or
        :data:`~.robust.UNDECIDED` (recompute those by another route; their
        ``max_real`` and frequency are NaN); ``max_real`` [1/s] and the
        frequency [Hz] of the root with the largest real part.

    Notes
    -----
    Every coefficient carries a rigorous bound of its rounding error; the
    roots are found by compiled Weierstrass (Durand-Kerner) sweeps and the
    verdict is read from the Gerschgorin disks of the generalized companion
    matrix ``diag(z) - 1 Wᵀ``, which contain every root of every polynomial
    within the coefficient bounds (:func:`~._compiled.charpoly_grid`).
    """
    from ._compiled import PARALLEL_MIN, charpoly_grid, charpoly_grid_chunks

    xo = np.ascontiguousarray(outer_values, dtype=float)
    yi = np.ascontiguousarray(inner_values, dtype=float)
    shape = (xo.size, yi.size)
    ok = np.ones(shape, dtype=np.bool_) if valid is None else np.ascontiguousarray(np.broadcast_to(valid, shape))
    codes = np.empty(shape, dtype=np.uint8)
    mr = np.empty(shape)
    fr = np.empty(shape)
    if xo.size * yi.size >= PARALLEL_MIN and xo.size > CHARPOLY_BLOCK:
        # blocks of rows in parallel; each block warm-starts itself (results independent of the thread count)
        charpoly_grid_chunks(table.Q, table.RQ, xo, yi, ok, bool(eigen), CHARPOLY_ACCURACY, codes, mr, fr,
                             CHARPOLY_BLOCK)
    else:
        charpoly_grid(table.Q, table.RQ, xo, yi, ok, bool(eigen), CHARPOLY_ACCURACY, codes, mr, fr)
    return codes, mr, fr
