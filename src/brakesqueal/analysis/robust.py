r"""Model-agnostic robust primitives for stability verdicts of ``M q'' + D q' + K q = 0`` (eq. 47).

Every verdict made with these functions is either *certified* — it holds for
every polynomial / matrix within the stated error bounds of the computed
one — or explicitly :data:`UNDECIDED`; nothing is ever guessed from a
floating-point sign that rounding could have flipped.

Verdict codes (``uint8``): :data:`UNSTABLE` = 0 (not asymptotically stable),
:data:`STABLE` = 1 (all roots in the open left half-plane), :data:`UNDECIDED`
= 2.  Maps and sweeps store an undecided point with status
:data:`STATUS_UNDECIDED` = 5.

Primitives
----------
Characteristic polynomials of any degree (``a_0 + a_1 λ + ... + a_m λ^m``,
ascending coefficients):

* :func:`routh_verdicts` — certified Routh–Hurwitz test in midpoint-radius
  interval arithmetic on power-of-two scaled coefficients (``λ -> 2^e λ``
  balances ``|a_0|`` and ``|a_m|``; every Routh row is rescaled by a power of
  two, so nothing overflows); input radii bound the coefficient errors.
* :func:`routh_exact` — the same test in exact rational arithmetic
  (:class:`fractions.Fraction`); decides every polynomial not exactly on the
  stability boundary.
* :func:`isolate_real_roots` — exact real-root isolation (plain Python
  integers, :mod:`._roots`: Descartes' rule of signs with bisection on a
  gcd-free basis) of several polynomials on any interval, e.g.
  ``(1e-100, 1e100)``, with disjoint isolating intervals.

Matrices (any ``n``):

* :func:`state_verdicts` — eigenvalues of any (power-of-two balanced) state
  matrix with a first-order condition-number bound ``|δλ_k| <= 10 κ_k η ‖B‖_F``
  (η: input perturbation plus backward error of the QR algorithm);
  :func:`eigen_verdicts` applies it to the ``2n × 2n`` state matrix of
  eq. (47), :func:`descriptor_verdicts` to ``E^-1 A`` of a descriptor system
  (massless pads kept as first-order states: every eigenvalue counts).

2-DOF closed form (``n = 2``):

* :func:`quartic_interval` — interval coefficients of the quartic from
  entries with radii.
* :func:`exact_trivial_entries` — the closed form evaluated in exact rational
  arithmetic at a parameter vector (for :func:`routh_exact`).

These are primitives: which of them decides a point is chosen in one place,
the verdict dispatcher (:mod:`brakesqueal.analysis.verdict`), whose route
modules call them; it also enforces the consistency rule (a point marked
stable has ``max_real < 0``, an unstable one ``max_real >= 0``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from fractions import Fraction
from typing import TYPE_CHECKING, Any

import numpy as np

from ._roots import isolate_real_roots

if TYPE_CHECKING:
    from ..codegen.engine import Engine

__all__ = [
    "UNSTABLE", "STABLE", "UNDECIDED", "STATUS_UNDECIDED", "INPUT_REL", "routh_verdicts", "routh_exact",
    "isolate_real_roots", "quartic_interval", "eigen_verdicts",
    "mp_roots_summary", "balanced_roots_summary", "bounded_verdict", "roots_summary", "exact_trivial_entries",
    "balance", "state_verdicts", "descriptor_verdicts",
    "extended_descriptor_verdict", "EXTENDED_VERDICT_MAX_SIZE", "mp_balanced", "extended_analysis", "extended_eigen",
    "state_analysis", "state_matrices", "descriptor_states",
]

UNSTABLE, STABLE, UNDECIDED = 0, 1, 2
#: Status code of a map / sweep point whose verdict could not be decided.
STATUS_UNDECIDED = 5
#: Default relative (norm-wise) perturbation assumed for matrices computed numerically
#: (numeric linearization, built models) when no rigorous bound is available.
INPUT_REL = 2.0 ** -42


# ---------------------------------------------------------------- polynomials
def routh_verdicts(coeffs: np.ndarray, radii: np.ndarray | None = None) -> np.ndarray:
    """Certified Routh–Hurwitz verdicts for a batch of real polynomials.

    Parameters
    ----------
    coeffs : array_like, shape (n, m + 1) or (m + 1,)
        Ascending coefficients ``a_0 .. a_m`` (any common scale; values may
        span the whole floating-point range).
    radii : array_like, optional
        Absolute error bounds of the coefficients (same shape; default 0:
        the coefficients are exact).

    Returns
    -------
    ndarray of uint8, shape (n,)
        :data:`STABLE` if every polynomial within the radii has all roots in
        the open left half-plane, :data:`UNSTABLE` if none has, otherwise (or
        for non-finite input) :data:`UNDECIDED`.

    Notes
    -----
    The Routh array is computed in midpoint-radius interval arithmetic
    (rounding of every operation included); each first-column sign is used
    only when its interval excludes zero.  Rows are rescaled by powers of two
    and ``λ -> 2^e λ`` balances the outer coefficients, both exact.
    """
    from ._pure import call

    A = np.ascontiguousarray(np.atleast_2d(np.asarray(coeffs, dtype=float)))
    R = np.zeros_like(A) if radii is None else np.ascontiguousarray(np.broadcast_to(
        np.atleast_2d(np.asarray(radii, dtype=float)), A.shape))
    out = np.empty(A.shape[0], dtype=np.uint8)
    call("routh_batch", A.shape[0], A, R, out)  # a few rows: plain Python (no numba import)
    return out


def routh_exact(coeffs: Sequence[Any]) -> int:
    """Exact Routh–Hurwitz verdict of ``Σ coeffs[k] λ^k`` (rational coefficients).

    Parameters
    ----------
    coeffs : sequence of int, Fraction, float or SymPy Rational
        Ascending coefficients; floats are taken as the exact binary rationals
        they represent.

    Returns
    -------
    int
        :data:`STABLE` or :data:`UNSTABLE`; :data:`UNDECIDED` only when a
        first-column entry is exactly zero (a root exactly on the imaginary
        axis or a degenerate array: the linearization does not decide) or the
        leading coefficient is zero.
    """
    a = [Fraction(int(c.p), int(c.q)) if hasattr(c, "p") and hasattr(c, "q") else Fraction(c) for c in coeffs]
    while len(a) > 1 and a[-1] == 0:
        a.pop()
    m = len(a) - 1
    if m == 0:
        return STABLE if a[0] != 0 else UNDECIDED
    if a[m] < 0:
        a = [-x for x in a]
    row0 = a[m::-2]
    row1 = a[m - 1::-2]
    n0 = len(row0)
    row1 = row1 + [Fraction(0)] * (n0 - len(row1) + 1)
    row0 = row0 + [Fraction(0)]
    for _ in range(2, m + 1):
        p = row1[0]
        if p == 0:
            return UNDECIDED
        if p < 0:
            return UNSTABLE
        q = row0[0] / p
        new = [row0[k + 1] - q * row1[k + 1] for k in range(n0)] + [Fraction(0)]
        row0, row1 = row1, new
    if row1[0] == 0:
        return UNDECIDED
    return STABLE if row1[0] > 0 else UNSTABLE


def _to_fraction(x: Any) -> Fraction:
    if isinstance(x, Fraction):
        return x
    if hasattr(x, "p") and hasattr(x, "q"):
        return Fraction(int(x.p), int(x.q))
    return Fraction(x)


# ---------------------------------------------------------------- matrices
def quartic_interval(E: np.ndarray, R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Interval coefficients ``a0..a4`` (ascending) of ``det(λ²M + λD + K)`` for 2×2 matrices.

    ``E`` holds the 12 entries of ``M, D, K`` (row-major, shape ``(n, 12)``),
    ``R`` their absolute error bounds; returns ``(A, RA)`` of shape ``(n, 5)``.
    """
    from ._pure import call

    E = np.ascontiguousarray(np.atleast_2d(E), dtype=float)
    R = np.ascontiguousarray(np.broadcast_to(np.atleast_2d(R), E.shape), dtype=float)
    A = np.empty((E.shape[0], 5))
    RA = np.empty((E.shape[0], 5))
    call("quartic_interval_batch", E.shape[0], E, R, A, RA)  # a few rows: plain Python (no numba import)
    return A, RA


def _state(M: np.ndarray, D: np.ndarray, K: np.ndarray) -> np.ndarray:
    """Balanced state matrices ``[[0, w I], [-M^-1 K / w, -M^-1 D]]`` (similar to eq. 47's; ``w`` a power of two)."""
    n = M.shape[-1]
    MK = np.linalg.solve(M, K)
    MD = np.linalg.solve(M, D)
    nk = np.sqrt(np.max(np.abs(MK), axis=(-2, -1)))
    w = np.ldexp(1.0, np.where(nk > 0, np.round(np.log2(np.where(nk > 0, nk, 1.0))), 0).astype(int))
    A = np.zeros(M.shape[:-2] + (2 * n, 2 * n))
    A[..., :n, n:] = np.eye(n) * w[..., None, None]
    A[..., n:, :n] = -MK / w[..., None, None]
    A[..., n:, n:] = -MD
    return A


def balance(S: np.ndarray, iterations: int = 12) -> np.ndarray:
    """Power-of-two diagonal similarity ``B = T^-1 S T`` of a batch of square matrices (exact, same eigenvalues).

    Parameters
    ----------
    S : ndarray, shape (N, m, m)
        Matrices (finite).
    iterations : int
        Sweeps of simultaneous row/column equilibration (like LAPACK's
        ``gebal`` without permutations).

    Returns
    -------
    ndarray, shape (N, m, m)
        The balanced matrices; off-diagonal row and column norms within a
        factor of about 2 of each other.
    """
    return balance_scaling(S, iterations)[0]


#: Batches from this size are balanced by the compiled kernel (:func:`~._compiled.balance_batch`).
BALANCE_COMPILED_MIN = 256


def balance_scaling(S: np.ndarray, iterations: int = 12) -> tuple[np.ndarray, np.ndarray]:
    """:func:`balance` and the diagonal ``t`` of its ``T`` (powers of 2), shape ``(N, m)``."""
    B = np.array(S, dtype=float, copy=True)
    if B.ndim == 3 and B.shape[0] >= BALANCE_COMPILED_MIN and np.all(np.isfinite(B)):
        from ._compiled import balance_batch

        t = np.empty(B.shape[:-1])
        balance_batch(B, t, iterations)
        return B, t
    m = B.shape[-1]
    t = np.ones(B.shape[:-1])
    off = ~np.eye(m, dtype=bool)
    with np.errstate(all="ignore"):
        for _ in range(iterations):
            A = np.abs(B) * off
            c = A.sum(axis=-2)
            r = A.sum(axis=-1)
            ok = (c > 0) & (r > 0) & np.isfinite(c) & np.isfinite(r)
            e = np.where(ok, np.round(0.5 * np.log2(np.where(ok, r / np.where(ok, c, 1.0), 1.0))), 0.0)
            if not np.any(e):
                break
            f = np.ldexp(1.0, e.astype(int))
            B *= f[..., None, :] / f[..., :, None]
            t *= f
    return B, t


def state_verdicts(S: np.ndarray, *, rel_input: float = INPUT_REL) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Verdicts from the eigenvalues of first-order state matrices with a condition-number error bound.

    Parameters
    ----------
    S : ndarray, shape (N, m, m)
        State matrices of ``xi' = S xi`` (any size; e.g. ``2n`` for eq. 47, or
        ``2n + k`` with ``k`` pad states kept, ``E^-1 A`` of a descriptor system).
    rel_input : float
        Assumed relative (norm-wise) error of the balanced state matrix from its inputs.

    Returns
    -------
    codes : ndarray of uint8, shape (N,)
        :data:`STABLE` if ``Re λ_k + b_k < 0`` for every eigenvalue,
        :data:`UNSTABLE` if ``Re λ_k - b_k > 0`` for one, else
        :data:`UNDECIDED` (also for non-finite input); ``b_k = 10 κ_k
        (rel_input + 4 m u) ‖B‖_F`` with ``B`` the balanced matrix
        (:func:`balance`) and the eigenvalue condition number ``κ_k =
        ‖x_k‖ ‖y_k‖ / |y_k^H x_k|`` (first-order perturbation bound; infinite
        for defective eigenvalues).
    max_real, frequency : ndarray, shape (N,)
        Largest real part [1/s] of the computed eigenvalues and ``|Im λ| / 2π``
        [Hz] of that eigenvalue (NaN for non-finite input).  By construction
        ``max_real < 0`` where the code is stable and ``max_real > 0`` where it
        is unstable.
    """
    codes, mr, fr, _, _ = state_analysis(S, rel_input=rel_input)
    return codes, mr, fr


def _col_norms(X: np.ndarray, axis: int) -> np.ndarray:
    """Euclidean norms of complex vectors along ``axis`` of a batch (``np.linalg.norm`` without its complex
    conjugate product: half the time on batches of small eigenvector matrices)."""
    sub = "nij,nij->nj" if axis == 1 else "nij,nij->ni"
    return np.sqrt(np.einsum(sub, X.real, X.real) + np.einsum(sub, X.imag, X.imag))


def _eig_kappa(B: np.ndarray, vectors: bool = False) -> Any:
    """Eigenvalues and their condition numbers ``‖x‖ ‖y‖ / |y^H x|`` (batched; per matrix where LAPACK fails);
    with ``vectors`` also the participation factors ``|W_ik V_ki|`` (state ``k``, eigenvalue ``i``; ``V`` the right
    eigenvectors, ``W = V^-1``: unchanged by a diagonal scaling of the states), NaN where LAPACK failed."""
    try:
        lam, V = np.linalg.eig(B)
    except np.linalg.LinAlgError:
        if B.shape[0] == 1:
            nan = (np.full(B.shape[:2], np.nan + 0j), np.full(B.shape[:2], np.inf))
            return (*nan, np.full(B.shape, np.nan)) if vectors else nan
        out = [_eig_kappa(B[i:i + 1], vectors) for i in range(B.shape[0])]
        return tuple(np.concatenate([o[j] for o in out]) for j in range(3 if vectors else 2))
    part = np.full(B.shape, np.nan)
    try:
        W = np.linalg.inv(V)
        kappa = _col_norms(V, 1) * _col_norms(W, 2)
        part = np.abs(V * np.swapaxes(W, 1, 2))
    except np.linalg.LinAlgError:
        if B.shape[0] == 1:
            kappa = np.full(lam.shape, np.inf)
        else:
            sub = [_eig_kappa(B[i:i + 1], True) for i in range(B.shape[0])]
            kappa = np.concatenate([o[1] for o in sub])
            part = np.concatenate([o[2] for o in sub])
    except ValueError:
        kappa = np.full(lam.shape, np.inf)
    kappa = np.where(np.isfinite(kappa), kappa, np.inf)
    return (lam, kappa, part) if vectors else (lam, kappa)


def state_analysis(S: np.ndarray, labels: np.ndarray | None = None, exclude: np.ndarray | None = None, *,
                   rel_input: float = INPUT_REL) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`state_verdicts` with the error bound and the carrier of the least-stable eigenvalue.

    Parameters
    ----------
    S : ndarray, shape (N, m, m)
        State matrices.
    labels : ndarray of int, shape (m,), optional
        A label per state (e.g. the component it belongs to); an eigenvalue is carried by the label with the
        largest sum of its states' participation factors ``|W_ik V_ki|`` (unit-free: unchanged by scaling a
        state).
    exclude : ndarray of int, optional
        Labels whose eigenvalues are left out of the verdict (reported, not judged).
    rel_input : float
        As :func:`state_verdicts`.

    Returns
    -------
    codes, max_real, frequency : ndarray, shape (N,)
        As :func:`state_verdicts` (over the eigenvalues not excluded).
    bound : ndarray, shape (N,)
        The error bound of the least-stable (judged) eigenvalue.
    carrier : ndarray of int, shape (N,)
        Its label (-1 without ``labels`` or a verdict).
    """
    S = np.asarray(S, dtype=float)
    N, m = S.shape[0], S.shape[-1]
    codes = np.full(N, UNDECIDED, dtype=np.uint8)
    mr = np.full(N, np.nan)
    fr = np.full(N, np.nan)
    bd = np.full(N, np.nan)
    car = np.full(N, -1, dtype=np.int64)
    if N == 0:
        return codes, mr, fr, bd, car
    with np.errstate(all="ignore"):
        good = np.all(np.isfinite(S), axis=(1, 2))
        idx = np.flatnonzero(good)
        if idx.size == 0:
            return codes, mr, fr, bd, car
        B = balance(S[idx])
        good2 = np.all(np.isfinite(B), axis=(1, 2))
        B[~good2] = 0.0
        lam, kappa, part = _eig_kappa(B, vectors=True)
        good2 &= np.all(np.isfinite(lam), axis=1)
        lam = np.where(np.isfinite(lam), lam, 0.0)
        eta = rel_input + 4.0 * m * 2.0 ** -53
        b = 10.0 * kappa * eta * np.linalg.norm(B, axis=(1, 2))[:, None]
        judged = np.ones(lam.shape, dtype=bool)
        own = None
        if labels is not None:
            lab = np.asarray(labels, dtype=np.int64)
            share = np.nan_to_num(part)  # (G, state, eigenvalue): participation factors
            nl = int(lab.max()) + 1 if lab.size else 1
            per = np.zeros((share.shape[0], nl, share.shape[2]))
            for j in range(nl):
                per[:, j, :] = share[:, lab == j, :].sum(axis=1)
            own = np.argmax(per, axis=1)  # (G, eigenvalue)
            if exclude is not None and len(exclude):
                judged = ~np.isin(own, np.asarray(exclude, dtype=np.int64))
        re = np.where(judged, lam.real, -np.inf)
        hi = np.max(np.where(judged, lam.real + b, -np.inf), axis=1)
        lo = np.max(np.where(judged, lam.real - b, -np.inf), axis=1)
        k = np.argmax(re, axis=1)
        rows = np.arange(idx.size)
        top = lam[rows, k]
        any_judged = np.any(judged, axis=1)
        c = np.where(hi < 0, STABLE, np.where(lo > 0, UNSTABLE, UNDECIDED)).astype(np.uint8)
        c[~good2] = UNDECIDED
        c[~any_judged] = STABLE  # nothing judged: every mode excluded (only pad-rate modes)
        codes[idx] = c
        mr[idx] = np.where(good2 & any_judged, top.real, np.nan)
        fr[idx] = np.where(good2 & any_judged, np.abs(top.imag) / (2 * np.pi), np.nan)
        bd[idx] = np.where(good2 & any_judged, b[rows, k], np.nan)
        if own is not None:
            car[idx] = np.where(good2 & any_judged, own[rows, k], -1)
    return codes, mr, fr, bd, car


def state_matrices(M: np.ndarray, D: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Balanced ``2n x 2n`` state matrices of eq. (47) for a batch, and which of them are usable.

    Returns
    -------
    S : ndarray, shape (N, 2n, 2n)
        ``[[0, w I], [-M^-1 K / w, -M^-1 D]]`` (``w`` a power of two; similar to eq. 47's state matrix);
        zeros where unusable.
    good : ndarray of bool, shape (N,)
        Finite matrices with a nonsingular ``M``.
    """
    M, D, K = (np.asarray(X, dtype=float) for X in (M, D, K))
    N, n = M.shape[0], M.shape[-1]
    S = np.zeros((N, 2 * n, 2 * n))
    with np.errstate(all="ignore"):
        good = np.all(np.isfinite(M), axis=(1, 2)) & np.all(np.isfinite(D), axis=(1, 2)) & \
            np.all(np.isfinite(K), axis=(1, 2))
        # singular means a zero pivot (slogdet's sign 0), not a determinant that underflows (a 172-DOF M of
        # entries 1e-3 has det 1e-516 = 0.0 in double precision)
        good &= np.linalg.slogdet(np.where(good[:, None, None], M, np.eye(n)))[0] != 0
        idx = np.flatnonzero(good)
        if idx.size:
            S[idx] = _state(M[idx], D[idx], K[idx])
    return S, good


def descriptor_states(E: np.ndarray, A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``E^-1 A`` of a batch of descriptor systems (LU with partial pivoting), and which of them are usable.

    Returns
    -------
    S : ndarray, shape (N, m, m)
        The state matrices (zeros where unusable).
    good : ndarray of bool, shape (N,)
        Finite systems with a nonsingular ``E`` (a singular one has an infinite eigenvalue).
    """
    E, A = np.asarray(E, dtype=float), np.asarray(A, dtype=float)
    N, m = E.shape[0], E.shape[-1]
    S = np.zeros((N, m, m))
    with np.errstate(all="ignore"):
        good = np.all(np.isfinite(E), axis=(1, 2)) & np.all(np.isfinite(A), axis=(1, 2))
        good &= np.linalg.slogdet(np.where(good[:, None, None], E, np.eye(m)))[0] != 0  # not det: it underflows
        idx = np.flatnonzero(good)
        if idx.size:
            try:
                S[idx] = np.linalg.solve(E[idx], A[idx])
            except np.linalg.LinAlgError:
                S[idx] = np.stack([_solve_or_nan(E[i], A[i]) for i in idx])
        good &= np.all(np.isfinite(S), axis=(1, 2))
    return S, good


def _usable_state_verdicts(S: np.ndarray, good: np.ndarray, rel_input: float
                           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`state_verdicts` of the usable state matrices ``S[good]``; :data:`UNDECIDED` and NaN elsewhere."""
    N = S.shape[0]
    codes = np.full(N, UNDECIDED, dtype=np.uint8)
    mr = np.full(N, np.nan)
    fr = np.full(N, np.nan)
    idx = np.flatnonzero(good)
    if idx.size:
        codes[idx], mr[idx], fr[idx] = state_verdicts(S[idx], rel_input=rel_input)
    return codes, mr, fr


def eigen_verdicts(M: np.ndarray, D: np.ndarray, K: np.ndarray, *, rel_input: float = INPUT_REL
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Verdicts from the eigenvalues of the state matrix of eq. (47) with a condition-number error bound.

    Parameters
    ----------
    M, D, K : ndarray, shape (N, n, n)
        Batched matrices of eq. (47).
    rel_input : float
        Assumed relative (norm-wise) error of the state matrix from its inputs.

    Returns
    -------
    codes, max_real, frequency : ndarray, shape (N,)
        See :func:`state_verdicts` (applied to the ``2n x 2n`` state matrices
        ``[[0, w I], [-M^-1 K / w, -M^-1 D]]``); singular or non-finite ``M``
        gives :data:`UNDECIDED`.
    """
    S, good = state_matrices(M, D, K)
    return _usable_state_verdicts(S, good, rel_input)


def descriptor_verdicts(E: np.ndarray, A: np.ndarray, *, rel_input: float = INPUT_REL
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Verdicts of descriptor systems ``E xi' = A xi`` (pads kept as first-order states) from every eigenvalue.

    Parameters
    ----------
    E, A : ndarray, shape (N, m, m)
        Batched descriptor matrices (e.g.
        :attr:`LinearModel.descriptor <brakesqueal.analysis.linear.LinearModel.descriptor>`).
    rel_input : float
        Assumed relative (norm-wise) error of the balanced state matrix ``E^-1 A``.

    Returns
    -------
    codes, max_real, frequency : ndarray, shape (N,)
        :func:`state_verdicts` of ``E^-1 A`` (LU with partial pivoting): every
        finite eigenvalue of the pencil, the pads' own modes included
        (e.g. ``lambda = -G_L/G_dL`` of a massless pad).  A singular ``E``
        (an infinite eigenvalue) gives :data:`UNDECIDED`.
    """
    S, good = descriptor_states(E, A)
    return _usable_state_verdicts(S, good, rel_input)


def mp_balanced(S: Any) -> tuple[Any, list[Any]]:
    """An mpmath matrix balanced by an exact diagonal similarity (powers of 2): ``(D^-1 S D, diag D)``.

    mpmath's QR iteration converged to wrong eigenvalues of a graded matrix (entries spanning 1e90), the same
    at 40 and 80 digits; balanced (:func:`balance_scaling`, run to the end) it does not.  ``D = I`` where the
    matrix does not fit in double precision.
    """
    import warnings

    import mpmath

    N = S.rows
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        Sd = np.array(S.tolist(), dtype=float)
        sc = balance_scaling(Sd[None], iterations=200)[1][0] if np.all(np.isfinite(Sd)) else np.ones(N)
    if not (np.all(np.isfinite(sc)) and np.all(sc > 0)):
        sc = np.ones(N)
    d = [mpmath.mpf(float(v)) for v in sc]
    return mpmath.matrix([[S[i, j] * d[j] / d[i] for j in range(N)] for i in range(N)]), d


#: Largest descriptor size :func:`extended_descriptor_verdict` takes (about 30 ms at size 6).
EXTENDED_VERDICT_MAX_SIZE = 12


def extended_descriptor_verdict(E: np.ndarray, A: np.ndarray, k: int, *, rel_input: float = INPUT_REL,
                                dps: int = 40) -> tuple[int, float, float, float, np.ndarray]:
    """Verdict of one descriptor system from extended-precision eigenvalues with componentwise bounds.

    The double-precision route (:func:`descriptor_verdicts`) bounds every
    eigenvalue's error by ``κ ε ‖B‖``: beside a massless pad's own mode of
    ``1e15``-``1e25`` (a tilted silent motion without normal dampers) that
    bound is far larger than the structural modes, which stay undecided.
    Here the pencil is taken as exact data with an error of at most
    ``rel_input`` relative to each entry.  In ``dps``-digit arithmetic
    (mpmath) the kept pads' algebraic rows (zero rows of ``E``) are
    eliminated, and every finite eigenvalue ``λ`` of ``E' ξ' = A' ξ`` gets
    the first-order componentwise bound ``δ = |y| (|A'| + |λ| |E'|) |x| /
    |y E' x|·rel_input`` (right and left eigenvectors ``x``, ``y``; ``|A'|``,
    ``|E'|`` the entries' magnitudes propagated through the elimination),
    which stays at the scale of each eigenvalue.

    Parameters
    ----------
    E, A : ndarray, shape (m, m)
        The descriptor (:attr:`LinearModel.descriptor
        <brakesqueal.analysis.linear.LinearModel.descriptor>`), ``m`` at most
        :data:`EXTENDED_VERDICT_MAX_SIZE`.
    k : int
        Number of pad states (the trailing ``k`` unknowns).
    rel_input : float
        Relative error of each entry.
    dps : int
        Decimal digits of the arithmetic.

    Returns
    -------
    code, max_real, frequency, bound, eigenvalues
        :data:`STABLE` if ``Re λ + 10 δ < 0`` for every eigenvalue,
        :data:`UNSTABLE` if ``Re λ - 10 δ > 0`` for one, else
        :data:`UNDECIDED` (also for a singular reduced ``E`` or no
        convergence); the least-stable eigenvalue's real part [1/s],
        frequency [Hz] and ``10 δ``; all finite eigenvalues (empty when
        undecided for want of them).
    """
    return extended_analysis(E, A, k, rel_input=rel_input, dps=dps)[:5]  # type: ignore[return-value]


def extended_eigen(E: np.ndarray, A: np.ndarray, k: int, *, rel_input: float = INPUT_REL, dps: int = 40
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Every finite eigenvalue of a descriptor system in extended precision, with componentwise error bounds.

    The computation behind :func:`extended_descriptor_verdict` without a verdict (see there for the method).

    Parameters
    ----------
    E, A, k, rel_input, dps
        As :func:`extended_descriptor_verdict`.

    Returns
    -------
    (eigenvalues, bounds, owner) or None
        The eigenvalues, their first-order componentwise bounds ``10 δ`` and, per eigenvalue, the state
        with the largest participation factor (an index of the original states); ``None``
        where they cannot be computed (too large, not finite, a singular reduced ``E``, no convergence).
    """
    import mpmath

    E, A = np.asarray(E, dtype=float), np.asarray(A, dtype=float)
    m = E.shape[0]
    if m > EXTENDED_VERDICT_MAX_SIZE or not (np.all(np.isfinite(E)) and np.all(np.isfinite(A))):
        return None
    rows = np.flatnonzero(np.all(E == 0.0, axis=1))
    keep_c = list(range(m))
    with mpmath.workdps(dps):
        mE, mA = mpmath.matrix(E.tolist()), mpmath.matrix(A.tolist())
        aE, aA = mpmath.matrix(np.abs(E).tolist()), mpmath.matrix(np.abs(A).tolist())
        if rows.size:
            if rows.size > k:
                return None
            import scipy.linalg

            pads = np.arange(m - k, m)
            _, _, piv = scipy.linalg.qr(A[np.ix_(rows, pads)], pivoting=True)
            cols = pads[np.sort(piv[:rows.size])]
            keep_r = [int(i) for i in np.setdiff1d(np.arange(m), rows)]
            keep_c = [int(i) for i in np.setdiff1d(np.arange(m), cols)]

            def sub(X: Any, r: Any, c: Any) -> Any:
                return mpmath.matrix([[X[int(i), int(j)] for j in c] for i in r])

            try:
                X = mpmath.inverse(sub(mA, rows, cols)) * sub(mA, rows, keep_c)
                aX = mpmath.matrix([[abs(v) for v in row] for row in X.tolist()])
            except ZeroDivisionError:
                return None
            mE = sub(mE, keep_r, keep_c) - sub(mE, keep_r, cols) * X
            mA = sub(mA, keep_r, keep_c) - sub(mA, keep_r, cols) * X
            aE = sub(aE, keep_r, keep_c) + sub(aE, keep_r, cols) * aX
            aA = sub(aA, keep_r, keep_c) + sub(aA, keep_r, cols) * aX
        try:
            Einv = mpmath.inverse(mE)
            Sb, dg = mp_balanced(Einv * mA)
            N = Sb.rows
            lam, ELb, ERb = mpmath.eig(Sb, left=True, right=True)
        except (ZeroDivisionError, mpmath.libmp.NoConvergence):
            return None
        out = np.empty(N, dtype=complex)
        bounds = np.empty(N)
        owner = np.zeros(N, dtype=np.int64)
        for i in range(N):
            # participation factors |w_r x_r| of the (balanced) left and right vectors: unit-free
            owner[i] = int(np.argmax([abs(complex(ELb[i, r] * ERb[r, i])) for r in range(N)]))
            x = mpmath.matrix([ERb[r, i] * dg[r] for r in range(N)])
            w = mpmath.matrix([[ELb[i, c] / dg[c] for c in range(N)]])
            y = w * Einv  # y A' = λ y E'
            den = abs((y * mE * x)[0, 0])
            ax = mpmath.matrix([abs(v) for v in x])
            ay = mpmath.matrix([[abs(v) for v in y]])
            num = (ay * (aA + abs(lam[i]) * aE) * ax)[0, 0]
            bounds[i] = float(10 * rel_input * num / den) if den > 0 else math.inf
            out[i] = complex(lam[i])
    tiny = np.abs(out.imag) <= 1e-30 * np.abs(out)
    out[tiny] = out[tiny].real
    return out, bounds, np.asarray(keep_c, dtype=np.int64)[owner]


def extended_analysis(E: np.ndarray, A: np.ndarray, k: int, labels: np.ndarray | None = None,
                      exclude: np.ndarray | None = None, *, rel_input: float = INPUT_REL, dps: int = 40
                      ) -> tuple[int, float, float, float, np.ndarray, int]:
    """:func:`extended_descriptor_verdict` with the carrier of its least-stable eigenvalue, optionally leaving out
    the eigenvalues of some carriers.

    Parameters
    ----------
    E, A, k, rel_input, dps
        As :func:`extended_descriptor_verdict`.
    labels : ndarray of int, shape (m,), optional
        A label per state; an eigenvalue is carried by the label of the state with the largest participation
        factor.
    exclude : ndarray of int, optional
        Labels whose eigenvalues are left out of the verdict.

    Returns
    -------
    code, max_real, frequency, bound, eigenvalues, carrier
        As :func:`extended_descriptor_verdict` (over the judged eigenvalues), and the carrier label of the
        least-stable judged one (-1 without ``labels``).
    """
    res = extended_eigen(E, A, k, rel_input=rel_input, dps=dps)
    if res is None:
        return UNDECIDED, math.nan, math.nan, math.inf, np.empty(0, dtype=complex), -1
    out, bounds, owner = res
    N = out.size
    carriers = np.full(N, -1, dtype=np.int64)
    judged = np.ones(N, dtype=bool)
    if labels is not None:
        lab = np.asarray(labels, dtype=np.int64)
        carriers = lab[owner]
        if exclude is not None and len(exclude):
            judged = ~np.isin(carriers, np.asarray(exclude, dtype=np.int64))
    code, mr, fr, bd, j = bounded_verdict(out, bounds, judged)
    return code, mr, fr, bd, out, (int(carriers[j]) if j >= 0 else -1)


def bounded_verdict(lam: np.ndarray, bounds: np.ndarray, judged: np.ndarray) -> tuple[int, float, float, float, int]:
    """The verdict of eigenvalues with error bounds, some of them judged (the others reported, not judged).

    Stable if every judged eigenvalue lies left of the imaginary axis by more than its bound, unstable if one
    lies right of it by more than its bound, undecided otherwise (stable when nothing is judged).

    Parameters
    ----------
    lam, bounds : ndarray, shape (m,)
        The eigenvalues and their error bounds.
    judged : ndarray of bool, shape (m,)
        Which count.

    Returns
    -------
    code, max_real, frequency, bound, index
        The verdict code; the least-stable judged eigenvalue's real part, frequency [Hz] and bound, and its index
        (NaN and -1 when nothing is judged).
    """
    if not judged.any():  # every mode excluded
        return STABLE, math.nan, math.nan, math.nan, -1
    j = int(np.argmax(np.where(judged, lam.real, -np.inf)))
    if np.all((lam.real + bounds < 0) | ~judged):
        code = STABLE
    elif np.any((lam.real - bounds > 0) & judged):
        code = UNSTABLE
    else:
        code = UNDECIDED
    return code, float(lam[j].real), float(abs(lam[j].imag) / (2 * math.pi)), float(bounds[j]), j




def _solve_or_nan(E: np.ndarray, A: np.ndarray) -> np.ndarray:
    try:
        return np.linalg.solve(E, A)
    except np.linalg.LinAlgError:
        return np.full(A.shape, np.nan)


def mp_roots_summary(coeffs: Sequence[Any], dps: int = 50) -> tuple[float, float]:
    """``(max Re λ, |Im λ|/2π)`` of the least-stable root of an exactly given polynomial, in mpmath."""
    import mpmath

    c = [_to_fraction(x) for x in coeffs]
    while len(c) > 1 and c[-1] == 0:
        c.pop()
    if len(c) < 2:
        return math.nan, math.nan
    with mpmath.workdps(dps):
        mc = [mpmath.mpf(x.numerator) / x.denominator for x in reversed(c)]
        try:
            r = mpmath.polyroots(mc, maxsteps=400, extraprec=4 * dps)
        except mpmath.libmp.NoConvergence:
            return math.nan, math.nan
        top = max(r, key=lambda z: mpmath.re(z))
        return float(mpmath.re(top)), float(abs(mpmath.im(top)) / (2 * mpmath.pi))


def roots_summary(A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``max Re λ`` and ``|Im λ|/2π`` of the least-stable root for a batch of polynomials (ascending rows).

    Companion-matrix eigenvalues after the exact power-of-two balancing
    ``λ -> 2^e λ`` used by :func:`routh_verdicts` (floating point).
    """
    A = np.atleast_2d(np.asarray(A, dtype=float))
    n, m1 = A.shape
    m = m1 - 1
    mr = np.full(n, np.nan)
    fr = np.full(n, np.nan)
    with np.errstate(all="ignore"):
        lead = A[:, m]
        a0 = A[:, 0]
        ok = np.all(np.isfinite(A), axis=1) & (lead != 0)
        e = np.where(ok & (a0 != 0), np.round((np.log2(np.abs(np.where(a0 != 0, a0, 1.0)))
                                                - np.log2(np.abs(np.where(lead != 0, lead, 1.0)))) / m), 0)
        e = np.where(np.isfinite(e), e, 0).astype(int)
        # λ = 2^e μ: b_k = a_k 2^(e k), roots μ = λ / 2^e
        B = np.ldexp(A, (e[:, None] * np.arange(m1)[None, :]))
        comp = np.zeros((n, m, m))
        comp[:, 0, :] = -B[:, m - 1::-1] / B[:, m:m + 1]
        if m > 1:
            comp[:, np.arange(1, m), np.arange(0, m - 1)] = 1.0
        ok &= np.all(np.isfinite(comp), axis=(1, 2))
        comp[~ok] = 0.0
        lam = np.linalg.eigvals(comp) * np.ldexp(1.0, e)[:, None]
        k = np.argmax(lam.real, axis=1)
        top = lam[np.arange(n), k]
    mr[ok] = top.real[ok]
    fr[ok] = np.abs(top.imag[ok]) / (2 * np.pi)
    return mr, fr


# ---------------------------------------------------------------- 2-DOF closed form, exact
def exact_trivial_entries(engine: Engine, p: Sequence[float]) -> list[Fraction]:
    """The 12 closed-form entries of ``M, D, K`` (trivial silent motion) evaluated exactly at parameter vector ``p``.

    Parameters
    ----------
    engine : Engine
        The model's engine; it needs a closed form.
    p : sequence of float
        Parameter vector in the model's packing order (compliances for
        tangential stiffnesses); each float is taken as the exact rational it
        represents.

    Returns
    -------
    list of Fraction
        ``M, D, K`` row-major (:meth:`Engine.exact_entries <brakesqueal.codegen.engine.Engine.exact_entries>`).
    """
    return list(engine.exact_entries().entries([Fraction(float(v)) for v in p]))


def _quartic_exact(e: Sequence[Fraction]) -> list[Fraction]:
    m11, m12, m21, m22, d11, d12, d21, d22, k11, k12, k21, k22 = e
    return [k11 * k22 - k12 * k21,
            d11 * k22 + k11 * d22 - d12 * k21 - k12 * d21,
            m11 * k22 + d11 * d22 + k11 * m22 - m12 * k21 - d12 * d21 - k12 * m21,
            m11 * d22 + d11 * m22 - m12 * d21 - d12 * m21,
            m11 * m22 - m12 * m21]


def _exact_point(engine: Engine, p: Sequence[float], eigen: bool) -> tuple[int, float, float]:
    try:
        q = _quartic_exact(exact_trivial_entries(engine, p))
    except (ZeroDivisionError, OverflowError, ValueError):  # singular closed form (invalid parameters)
        return UNDECIDED, math.nan, math.nan
    code = routh_exact(q)
    if not eigen:
        return code, math.nan, math.nan
    mr, fr = balanced_roots_summary(q)
    # the double-precision roots of the balanced polynomial serve where their sign is the exact verdict's
    # (the verdict is Routh's, exact); near the boundary or beyond double's range, 50-digit roots
    if not (math.isfinite(mr) and ((code == STABLE and mr < 0) or (code == UNSTABLE and mr >= 0))):
        mr, fr = mp_roots_summary(q)
    return code, mr, fr


def _log2(x: Fraction) -> int:
    """``floor(log2 |x|)`` to within one, of an exact nonzero rational, without converting it to a float."""
    return x.numerator.bit_length() - x.denominator.bit_length() if x > 0 else \
        (-x).numerator.bit_length() - x.denominator.bit_length()


#: Bits by which a coefficient must fall below a group's largest to be left out of that group's roots.
_GAP_BITS = 80


def balanced_roots_summary(coeffs: Sequence[Fraction]) -> tuple[float, float]:
    """``(max Re λ, |Im λ|/2π)`` of an exactly given polynomial's least-stable root, from double precision.

    The roots are found in groups of one magnitude, read off the Newton polygon of the exact coefficients
    (the upper convex hull of ``(k, log2 |a_k|)``: an edge from ``i`` to ``j`` holds ``j - i`` roots of modulus
    about ``2^s``, ``s = (log2|a_i| - log2|a_j|)/(j - i)``; adjacent edges whose other coefficients are not
    ``2^-80`` below are merged).  Per group the coefficients ``a_i .. a_j`` are scaled exactly (``λ = 2^s μ``),
    divided by the largest and only then rounded, so that coefficients spanning far more than double's range
    (parameters at the magnitude bounds, roots from ``1e-100`` to ``1e100``) still give every root.  Each root
    is then polished by Newton's method on the exact polynomial in 50-digit arithmetic and accepted only if
    its residual is at rounding level and the roots are distinct; NaN otherwise (then
    :func:`mp_roots_summary`).  About 100 times faster than :func:`mp_roots_summary`, which also fails on
    such spreads.

    Parameters
    ----------
    coeffs : sequence of Fraction
        Ascending exact coefficients.

    Returns
    -------
    (float, float)
    """
    import mpmath

    c = [Fraction(x) for x in coeffs]
    while len(c) > 1 and c[-1] == 0:
        c.pop()
    low = 0
    while low < len(c) - 1 and c[low] == 0:  # roots at 0
        low += 1
    m = len(c) - 1
    if m < 1:
        return math.nan, math.nan
    pts = [(k, _log2(c[k])) for k in range(low, m + 1) if c[k] != 0]
    hull: list[tuple[int, int]] = []
    for pt in pts:  # upper convex hull (monotone chain)
        while len(hull) >= 2 and ((hull[-1][0] - hull[-2][0]) * (pt[1] - hull[-2][1])
                                  - (hull[-1][1] - hull[-2][1]) * (pt[0] - hull[-2][0])) >= 0:
            hull.pop()
        hull.append(pt)
    edges = [[i, j, (li - lj) / (j - i)] for (i, li), (j, lj) in zip(hull[:-1], hull[1:])]
    groups = [edges[0]] if edges else []
    for e in edges[1:]:
        g = groups[-1]
        if (e[2] - g[2]) * min(e[1] - e[0], g[1] - g[0]) < _GAP_BITS:  # not separated: one group
            g[2] = (g[2] * (g[1] - g[0]) + e[2] * (e[1] - e[0])) / (e[1] - g[0])
            g[1] = e[1]
        else:
            groups.append(e)
    starts: list[tuple[complex, int]] = []  # root = mu 2^sc
    with np.errstate(all="ignore"):
        for gi, gj, s in groups:
            i, j, sc = int(gi), int(gj), round(s)
            scaled = [c[k] * Fraction(2) ** (sc * k) for k in range(i, j + 1)]
            big = max(abs(x) for x in scaled)
            b = [float(x / big) if abs(x) >= big / 2 ** 1000 else 0.0 for x in scaled]
            mu = np.roots(b[::-1])
            if mu.size != j - i or not np.all(np.isfinite(mu)):
                return math.nan, math.nan
            starts += [(complex(z), sc) for z in mu]
    if len(starts) != m - low:
        return math.nan, math.nan
    with mpmath.workdps(50):
        approx = [mpmath.mpc(z) * mpmath.ldexp(1, sc) for z, sc in starts]
        a = [mpmath.mpf(x.numerator) / x.denominator for x in c]
        da = [k * a[k] for k in range(1, m + 1)]
        roots = []
        for z0 in approx:
            z = mpmath.mpc(z0)
            for _ in range(4):
                d = mpmath.polyval(da[::-1], z)
                if d == 0:
                    break
                z -= mpmath.polyval(a[::-1], z) / d
            size = mpmath.polyval([abs(v) for v in a[::-1]], abs(z))
            if size == 0 or abs(mpmath.polyval(a[::-1], z)) > size * mpmath.mpf(2) ** -140:
                return math.nan, math.nan
            roots.append(z)
        for p_, q_ in ((p_, q_) for k, p_ in enumerate(roots) for q_ in roots[k + 1:]):
            if abs(p_ - q_) <= mpmath.mpf(2) ** -60 * max(abs(p_), abs(q_)):
                return math.nan, math.nan  # two starts polished onto one root
        roots += [mpmath.mpc(0)] * low
        top = max(roots, key=lambda z: mpmath.re(z))
        return float(mpmath.re(top)), float(abs(mpmath.im(top)) / (2 * mpmath.pi))
