r"""Route ``pencil-refined``: QZ eigenpairs of the pencil, refined, with componentwise bounds (double precision).

Applies to linear systems of at most :data:`PENCIL_MAX_SIZE` states whose pencil ``A - λ E``
(:meth:`~._base.LinearGroup.descriptor`: eq. (47) in first-order form, or the descriptor system of pads kept as
states) has no algebraic row.  It decides what
:mod:`.eigen_bounds` leaves undecided beside a massless pad's own mode of ``1e10``–``1e15``: that mode lives
in a tiny entry of ``E``, so ``E^-1 A`` (and its norm-wise bound) is dominated by it, while the pencil keeps
the slow structural modes as well conditioned as they are.

Per system, every eigenpair of the pencil is computed by QZ (LAPACK ``ggev``, left and right vectors), and each
judged one is refined by Newton's method on ``(A - λE) x = 0`` with one normalised component (three steps, in
double precision).  The refined pair ``(λ, x)`` is an exact eigenpair of a pencil perturbed componentwise by at
most its Oettli–Prager backward error

.. math:: ω = \max_i |r_i| / ((|A| + |λ||E|)|x|)_i + (m + 3) u,\qquad r = (A - λE) x

(the second term covers the rounding of ``r``), so that, with the relative input error ``ε`` of every entry
(:data:`~..robust.INPUT_REL`), the first-order componentwise bound is

.. math:: |δλ| ≤ 10\,(ε + ω)\,\frac{|y|^T (|A| + |λ||E|) |x|}{|y^H E x|}

(the left vector ``y`` refined alike) — the bound of the 40-digit :mod:`.extended` route, here about 60 times
faster.  A refinement is accepted only if it stays within the QZ eigenvalue's own norm-wise bound and the
refined eigenvalues stay apart by more than their bounds (no two converged to one); otherwise the system is
left to :mod:`.extended`.  Eigenvalues are attributed to carriers by participation ``|(E^H y)_i x_i|`` (the
rule of :func:`~..robust.state_analysis`); with ``modes="disk"`` a massless pad's own modes are left out.
"""

from __future__ import annotations

import math

import numpy as np

from ..robust import INPUT_REL, UNDECIDED, bounded_verdict
from ._base import Context, Result, Route
from .eigen_bounds import pencil_route

__all__ = ["PencilRefined", "pencil_analysis", "PENCIL_MAX_SIZE"]

_U = 2.0 ** -53
#: Largest pencil the route takes: each eigenpair is refined by its own Newton solves (O(m^4) a system), which
#: pays for the small systems of massless pads (2-DOF models with pads: 6 states; eight-dof: 20), not for a
#: finite-element model's hundreds of states (those the norm-wise and sparse box routes decide).
PENCIL_MAX_SIZE = 32
#: Newton steps of each eigenpair's refinement.
_STEPS = 3


def _refine(A: np.ndarray, E: np.ndarray, lam: complex, x: np.ndarray) -> tuple[complex, np.ndarray]:
    """Newton's method on ``(A - λE) x = 0``, ``x_j = 1`` (``j`` its largest component)."""
    m = A.shape[0]
    j = int(np.argmax(np.abs(x)))
    x = x / x[j]
    J = np.zeros((m + 1, m + 1), dtype=complex)
    J[m, j] = 1.0
    rhs = np.zeros(m + 1, dtype=complex)
    for _ in range(_STEPS):
        J[:m, :m] = A - lam * E
        J[:m, m] = -(E @ x)
        rhs[:m] = -(J[:m, :m] @ x)
        d = np.linalg.solve(J, rhs)
        x = x + d[:m]
        lam = lam + complex(d[m])
    return complex(lam), x


def _backward_error(A: np.ndarray, E: np.ndarray, lam: complex, x: np.ndarray) -> float:
    """Componentwise (Oettli–Prager) backward error of an eigenpair, plus the rounding of its residual."""
    m = A.shape[0]
    r = np.abs((A - lam * E) @ x)
    scale = (np.abs(A) + abs(lam) * np.abs(E)) @ np.abs(x)
    if np.any((scale == 0) & (r > 0)):
        return math.inf
    with np.errstate(all="ignore"):
        om = float(np.max(np.where(scale > 0, r / np.where(scale > 0, scale, 1.0), 0.0)))
    return om + (m + 3) * _U


def _eigenpair(P: np.ndarray, Q: np.ndarray, z0: complex, x0: np.ndarray, y0: np.ndarray, labels: np.ndarray,
               rel_input: float) -> tuple[complex, float, int] | None:
    """One eigenvalue ``z`` of ``P - z Q`` refined from QZ's, its componentwise bound and its carrier label
    (``None`` if the refinement cannot be accepted)."""
    m = P.shape[0]
    eta = rel_input + 4.0 * m * _U
    den0 = abs(np.conj(y0) @ Q @ x0)
    if not (math.isfinite(z0.real) and math.isfinite(z0.imag)) or den0 == 0:
        return None
    owner = int(labels[int(np.argmax(np.abs((np.conj(y0) @ Q) * x0)))])
    # the QZ eigenvalue's own norm-wise first-order bound: the refinement must stay within it
    nw = 10.0 * eta * float(np.linalg.norm(x0) * np.linalg.norm(y0)) * (
        float(np.linalg.norm(P)) + abs(z0) * float(np.linalg.norm(Q))) / den0
    try:
        z, x = _refine(P, Q, z0, x0)
        _, y = _refine(P.T, Q.T, z.conjugate(), y0)  # left vector: (P - zQ)^H y = 0
    except np.linalg.LinAlgError:
        return None
    om = _backward_error(P, Q, z, x)
    den = abs(np.conj(y) @ Q @ x)
    if not (math.isfinite(om) and den > 0 and abs(z - z0) <= nw):
        return None
    bd = 10.0 * (rel_input + om) * float(np.abs(y) @ (np.abs(P) + abs(z) * np.abs(Q)) @ np.abs(x)) / den
    return (z, bd, owner) if math.isfinite(bd) else None


def pencil_analysis(E: np.ndarray, A: np.ndarray, labels: np.ndarray, exclude: np.ndarray | None = None, *,
                    rel_input: float = INPUT_REL) -> tuple[int, float, float, float, int]:
    """Certified verdict of one pencil ``A - λE`` from refined QZ eigenpairs (see the module docstring).

    An eigenvalue beyond ``‖A‖/‖E‖`` (a massless pad's own mode, up to ``1e22``; QZ may return it as
    infinite) is refined as ``μ = 1/λ`` of the reversed pencil ``E - μA``, whose bound decides the sign of
    ``Re λ = Re μ / |μ|²`` alike.

    Parameters
    ----------
    E, A : ndarray, shape (m, m)
        The pencil (real, finite; no zero row in ``E``).
    labels : ndarray of int, shape (m,)
        The carrier label of every state.
    exclude : ndarray of int, optional
        Labels whose eigenvalues are left out of the verdict.
    rel_input : float
        Relative error of every entry of the input.

    Returns
    -------
    code, max_real, frequency, bound, carrier
        :data:`~..robust.STABLE`, :data:`~..robust.UNSTABLE` or :data:`~..robust.UNDECIDED`; the least-stable
        judged eigenvalue's real part [1/s], frequency [Hz] and bound, and its carrier label.
    """
    import scipy.linalg

    undecided = (UNDECIDED, math.nan, math.nan, math.inf, -1)
    m = A.shape[0]
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(E))) or np.any(np.all(E == 0.0, axis=1)):
        return undecided
    try:
        (al, be), vl, vr = scipy.linalg.eig(A, E, left=True, right=True, homogeneous_eigvals=True)
    except (np.linalg.LinAlgError, ValueError):
        return undecided
    nA, nE = float(np.linalg.norm(A)), float(np.linalg.norm(E))
    lams, bounds, owners = [], [], []
    with np.errstate(all="ignore"):
        for i in range(m):
            a, b = complex(al[i]), complex(be[i])
            if abs(a) * nE <= abs(b) * nA:  # |λ| <= ‖A‖/‖E‖: the pencil as it is
                got = _eigenpair(A, E, a / b, vr[:, i], vl[:, i], labels, rel_input)
                if got is None:
                    return undecided
                lam, bd, owner = got
            else:  # the reversed pencil E - μA, μ = 1/λ
                got = _eigenpair(E, A, b / a, vr[:, i], vl[:, i], labels, rel_input)
                if got is None:
                    return undecided
                mu, bmu, owner = got
                if not abs(mu) > 2.0 * bmu:
                    return undecided
                lam = 1.0 / mu
                # Re λ = Re μ / |μ|²: its sign is certified with Re μ's; the bound of λ to first order
                bd = bmu / (abs(mu) * (abs(mu) - bmu)) if abs(mu.real) > bmu else math.inf
            lams.append(lam)
            bounds.append(bd)
            owners.append(owner)
        lam_a, bd_a, own_a = np.array(lams), np.array(bounds), np.array(owners, dtype=np.int64)
        # two eigenvalues refined into one would leave one unaccounted for
        gap = np.abs(lam_a[:, None] - lam_a[None, :])
        np.fill_diagonal(gap, np.inf)
        if np.any(gap <= bd_a[:, None] + bd_a[None, :]):
            return undecided
    skip = np.asarray(exclude if exclude is not None else [], dtype=np.int64)
    code, mr, fr, bd, j = bounded_verdict(lam_a, bd_a, ~np.isin(own_a, skip))
    return code, mr, fr, bd, (int(own_a[j]) if j >= 0 else -1)


class PencilRefined(Route):
    """See the module docstring."""

    name = "pencil-refined"
    description = "QZ eigenpairs of the pencil refined by Newton's method, with componentwise error bounds"

    def applies(self, ctx: Context) -> bool:
        return True

    def run(self, ctx: Context, idx: np.ndarray) -> Result:
        return pencil_route(ctx, idx, PENCIL_MAX_SIZE,
                            lambda E, A, k, labels, skip: pencil_analysis(E, A, labels, skip))
