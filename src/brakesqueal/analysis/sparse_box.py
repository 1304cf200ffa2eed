r"""Eigenvalues of a large sparse quadratic eigenvalue problem inside a box of the complex plane.

The finite-element brake models (e.g. the TU Berlin disk brake of Gräbner, Mehrmann, Quraishi,
Schröder and von Wagner, ZAMM 96 (2016) 1388–1405) give

.. math::  Q(\lambda)\,x = (\lambda^2 M + \lambda D + K)\,x = 0,

too large for a dense QZ per parameter point.  Only the eigenvalues in a box
``re_lo <= Re λ <= re_hi``, ``f_lo <= Im λ / 2π <= f_hi`` (the squeal-relevant band; the
conjugates are implied for real matrices) are wanted.  :func:`box_eigenvalues` finds them by
shift-and-invert Arnoldi on the first companion linearization

.. math::  A - \lambda B, \quad A = \begin{pmatrix} 0 & I \\ -K & -D \end{pmatrix},\quad
           B = \begin{pmatrix} I & 0 \\ 0 & M \end{pmatrix}, \quad v = \begin{pmatrix} x \\ \lambda x
           \end{pmatrix}

(Tisseur & Meerbergen, SIAM Review 43 (2001) 235–286, eq. 3.6): for a shift ``σ`` the operator
``T = (A - σB)^{-1} B`` has the eigenvalues ``θ = 1/(λ - σ)``, so its dominant eigenvalues
(ARPACK, ``scipy.sparse.linalg.eigs``) are the ``k`` eigenvalues ``λ`` nearest to ``σ``.
``(A - σB)^{-1}`` is applied through the block elimination of ``A - σB`` whose Schur complement
is ``-Q(σ)``:

.. math::  (A - \sigma B)\begin{pmatrix} x_1 \\ x_2 \end{pmatrix} = \begin{pmatrix} y_1 \\ y_2
           \end{pmatrix} \iff x_1 = -Q(\sigma)^{-1}\bigl(y_2 + (D + \sigma M)\,y_1\bigr),\;
           x_2 = y_1 + \sigma x_1,

i.e. one sparse LU (SuperLU, ``scipy.sparse.linalg.splu``) of the ``n × n`` matrix ``Q(σ)``
instead of the ``2n × 2n`` pencil (the same operator, about three times cheaper).

**Trusted discs and completeness.**  For a shift ``σ`` whose ``k`` Ritz values all converged,
the disc ``|λ - σ| < r``, ``r`` the distance of the farthest converged Ritz value, contains no
eigenvalue other than those found (ARPACK returns the ``k`` eigenvalues of largest ``|θ|``).
Shifts are placed along the box's centre line ``Re σ = (re_lo + re_hi)/2``, adaptively from
``f_lo`` upwards, until the box is covered by the union of the discs (conservatively: the
horizontal strip of the box inscribed in each disc).  The result is ``complete`` when

* the box is covered within ``max_shifts`` shifts,
* every Arnoldi run converged,
* neighbouring shifts agree: every eigenvalue found by one shift that lies inside another
  shift's disc was found by that shift too (to a relative ``1e-7``), and
* the run on the transposed problem (for the left eigenvectors) found the same eigenvalues.

This is a criterion in practice, not a proof (Arnoldi can in principle miss an eigenvalue whose
eigenvector is nearly orthogonal to the starting vector); the cross-checks between overlapping
discs make such a miss unlikely to go unnoticed.  When any of them fails the verdict is
``"undecided: ..."`` naming what was not resolved.

**Error bounds.**  For an eigenpair ``(λ, x)`` with residual ``r = Q(λ)x`` the pair is exact for
``Q + ΔQ`` with ``ΔQ(λ) = -r x^H/‖x‖²`` (backward error ``η = ‖r‖ / ((|λ|²‖M‖ + |λ|‖D‖ +
‖K‖)‖x‖)``, Tisseur, Linear Algebra Appl. 309 (2000) 339–361, Thm. 1); with the left eigenvector
``y`` (``y^H Q(λ) = 0``) first-order perturbation theory moves the eigenvalue by at most

.. math::  |\lambda_\ast - \lambda| \le \frac{\|y\|\,\bigl(\|r\| + \rho\bigr)}{|y^H Q'(\lambda) x|},
           \qquad Q'(\lambda) = 2\lambda M + D,

(= condition number × backward error, Tisseur 2000, Thm. 5), ``ρ = γ_m ‖ |K||x| + |λ||D||x| +
|λ|²|M||x| ‖`` (``γ_m = mu/(1 - mu)``, ``m`` the longest row plus 3; Higham, *Accuracy and
Stability*, §3.5) covering the rounding error of the computed residual itself.  ``bounds`` holds this bound of
the distance between each reported eigenvalue and the nearest exact eigenvalue of the given
``(M, D, K)`` (absolute, in the units of ``λ``).  It is first order (certified in practice, not
rigorously): it neglects ``O(η²)`` terms, which matter only for nearly multiple eigenvalues.  The
eigenvalue is refined by the two-sided Rayleigh quotient ``y^H Q(λ) x = 0`` (kept when its
residual is smaller).  The Ritz vectors of shift-and-invert Arnoldi have residuals of about
``tol ‖K‖``; an eigenvalue whose bound straddles ``Re λ = 0`` is therefore polished by up to three
steps of two-sided inverse iteration with a sparse LU of ``Q(λ)`` itself (kept when its bound
shrinks) before it is declared undecided.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Union

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from ..errors import ParameterError

__all__ = ["BoxResult", "ShiftRecord", "box_eigenvalues", "qep_residuals"]

#: A coefficient matrix: dense ndarray or any scipy.sparse matrix/array.
Matrix = Union[np.ndarray, sp.spmatrix, sp.sparray]

_U = np.finfo(float).eps / 2
#: Relative distance under which two Ritz values of different runs are the same eigenvalue.
_MATCH = 1e-7
#: Column orderings tried for the sparse LU (FE matrices often come band-ordered: NATURAL may win).
_ORDERINGS = ("MMD_AT_PLUS_A", "NATURAL")
#: An Arnoldi eigenvalue with ``|Im λ| <= _REAL |λ - σ|`` is taken as real (its Ritz error is far smaller).
_REAL = 1e-8
#: A point is strictly inside a disc when its distance is below ``(1 - _EDGE) r``.
_EDGE = 1e-6


@dataclass(frozen=True)
class ShiftRecord:
    """One shift-and-invert Arnoldi run.

    Attributes
    ----------
    sigma : complex
        The shift.
    radius : float
        Radius of the trusted disc ``|λ - σ| < radius`` (0 when the run failed).
    k : int
        Number of eigenvalues requested.
    eigenvalues : numpy.ndarray
        All converged Ritz values of the run (complex).
    converged : bool
        Whether all ``k`` Ritz values converged.
    """

    sigma: complex
    radius: float
    k: int
    eigenvalues: np.ndarray
    converged: bool


@dataclass(frozen=True)
class BoxResult:
    """Eigenvalues of ``λ²M + λD + K`` inside a box, with error bounds and a verdict.

    Attributes
    ----------
    eigenvalues : numpy.ndarray
        Complex eigenvalues found inside the box, by decreasing real part (``Im λ >= 0``; the
        conjugates of a real problem are implied).
    bounds : numpy.ndarray
        Per eigenvalue, a first-order bound of ``|λ_exact - λ|`` (absolute, units of ``λ``):
        ``‖y‖(‖r‖ + ρ)/|y^H(2λM + D)x|`` = condition number × backward error of the residual
        ``r = Q(λ)x`` (module docstring).  ``inf`` where no left eigenvector was found.
    vectors : numpy.ndarray or None
        Right eigenvectors ``x`` (``n × len(eigenvalues)``, unit 2-norm), when requested.
    box : tuple of float
        ``(re_lo, re_hi, f_lo, f_hi)``; ``f = Im λ / 2π`` [Hz].
    complete : bool
        Whether every eigenvalue of the box is (in practice) found: box covered by the trusted
        discs of converged shifts, neighbouring shifts consistent, left run consistent.
    unstable : int
        Number of eigenvalues with ``Re λ - bound > 0``.
    undecided : int
        Number of eigenvalues with ``|Re λ| <= bound`` (the bound straddles ``Re λ = 0``).
    verdict : str
        ``"stable in box"``, ``"k unstable modes in [f1, f2] Hz"`` or
        ``"undecided: <what was not resolved>"``.
    shifts : tuple of complex
        The shifts used, in the order computed.
    records : tuple of ShiftRecord
        Per shift: radius, Ritz values, convergence (diagnostics).
    notes : tuple of str
        What prevented completeness, if anything.
    left_vectors : numpy.ndarray or None
        Left eigenvectors ``y`` (``y^H Q(λ) = 0``; ``n × len(eigenvalues)``, unit 2-norm; a column of NaN
        where the transposed run found none), when ``vectors`` are requested.
    """

    eigenvalues: np.ndarray
    bounds: np.ndarray
    vectors: np.ndarray | None
    box: tuple[float, float, float, float]
    complete: bool
    unstable: int
    undecided: int
    verdict: str
    shifts: tuple[complex, ...]
    records: tuple[ShiftRecord, ...] = field(default=(), repr=False)
    notes: tuple[str, ...] = ()
    left_vectors: np.ndarray | None = field(default=None, repr=False)

    @property
    def frequencies(self) -> np.ndarray:
        """Frequencies ``Im λ / 2π`` [Hz] of :attr:`eigenvalues`."""
        return np.abs(self.eigenvalues.imag) / (2 * math.pi)


# --------------------------------------------------------------------------------------------- input checks


def _as_matrix(X: Any, name: str) -> sp.csc_matrix:
    """Check one coefficient matrix (square, real, finite) and return it as CSC."""
    if sp.issparse(X):
        S = sp.csc_matrix(X)
    else:
        try:
            arr = np.asarray(X)
        except Exception as exc:  # pragma: no cover - exotic input
            raise ParameterError(f"{name} must be a matrix (ndarray or scipy.sparse), got {type(X).__name__}",
                                 parameter=name) from exc
        if arr.ndim != 2:
            raise ParameterError(f"{name} must be a 2-D matrix, got shape {arr.shape}", parameter=name)
        if arr.dtype == object or not np.issubdtype(arr.dtype, np.number):
            raise ParameterError(f"{name} must be numeric, got dtype {arr.dtype}", parameter=name)
        S = sp.csc_matrix(arr)
    if S.shape[0] != S.shape[1] or S.shape[0] == 0:
        raise ParameterError(f"{name} must be square and non-empty, got shape {S.shape}", parameter=name)
    if np.iscomplexobj(S.data):
        if np.any(S.data.imag != 0):
            raise ParameterError(f"{name} must be real (the box is on Im λ >= 0, conjugates implied)",
                                 parameter=name)
        S = sp.csc_matrix(S.real)
    if not np.all(np.isfinite(S.data)):
        raise ParameterError(f"{name} has NaN or infinite entries", parameter=name)
    return S.astype(float)


def _check_box(re: tuple[float, float], freq: tuple[float, float]) -> tuple[float, float, float, float]:
    """Validate ``re = (re_lo, re_hi)`` and ``freq = (f_lo, f_hi)`` [Hz]."""
    try:
        re_lo, re_hi = (float(v) for v in re)
        f_lo, f_hi = (float(v) for v in freq)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"re and freq must be pairs of numbers, got re={re!r}, freq={freq!r}",
                             parameter="re") from exc
    if not all(math.isfinite(v) for v in (re_lo, re_hi, f_lo, f_hi)):
        raise ParameterError(f"box limits must be finite, got re={re!r}, freq={freq!r}", parameter="re")
    if re_lo >= re_hi:
        raise ParameterError(f"re = ({re_lo}, {re_hi}): need re_lo < re_hi", parameter="re")
    if f_lo < 0:
        raise ParameterError(f"freq = ({f_lo}, {f_hi}): f_lo must be >= 0 (conjugates are implied)",
                             parameter="freq")
    if f_lo >= f_hi:
        raise ParameterError(f"freq = ({f_lo}, {f_hi}): empty box, need f_lo < f_hi", parameter="freq")
    return re_lo, re_hi, f_lo, f_hi


# --------------------------------------------------------------------------------------------- the operator


class _ShiftInvert:
    """``(A - σB)^{-1} B`` of the companion pencil via the sparse LU of ``Q(σ)`` (module docstring).

    With ``transpose=True`` the same for the transposed QEP ``(M^T, D^T, K^T)`` (same LU, solved
    with ``trans='T'``): its right eigenvectors are the conjugated left eigenvectors of ``Q``.
    """

    def __init__(self, M: sp.csc_matrix, D: sp.csc_matrix, K: sp.csc_matrix, sigma: complex,
                 permc: str | None = None) -> None:
        self.n = M.shape[0]
        self.sigma = sigma
        Q = (K + sigma * D + (sigma * sigma) * M).tocsc().astype(complex)
        if permc is None:  # the first shift: keep the column ordering with the least fill
            lus = {p: sla.splu(Q, permc_spec=p) for p in _ORDERINGS}
            permc = min(lus, key=lambda p: lus[p].L.nnz + lus[p].U.nnz)
            self.lu = lus[permc]
        else:
            self.lu = sla.splu(Q, permc_spec=permc)
        self.permc = permc
        self.M, self.Mt = M.tocsr(), M.T.tocsr()
        self.DsM = (D + sigma * M).tocsr()
        self.DsMt = self.DsM.T.tocsr()

    def operator(self, transpose: bool) -> sla.LinearOperator:
        n, s, lu = self.n, self.sigma, self.lu
        Mx, DsM, trans = (self.Mt, self.DsMt, "T") if transpose else (self.M, self.DsM, "N")

        def matvec(v: np.ndarray) -> np.ndarray:
            v = np.asarray(v).reshape(-1)
            y1 = v[:n]
            x1 = -lu.solve(np.ascontiguousarray(Mx @ v[n:] + DsM @ y1, dtype=complex), trans=trans)
            return np.concatenate([x1, y1 + s * x1])

        return sla.LinearOperator((2 * n, 2 * n), matvec=matvec, dtype=complex)


def _arnoldi(op: sla.LinearOperator, k: int, tol: float, v0: np.ndarray) -> tuple[np.ndarray, np.ndarray, bool]:
    """``k`` dominant eigenpairs of ``op`` (ARPACK); one retry with a larger subspace on non-convergence."""
    N = op.shape[0]
    for ncv in (min(N, max(2 * k + 1, 20)), min(N, max(4 * k + 1, 40))):
        try:
            th, V = sla.eigs(op, k=k, which="LM", tol=tol, v0=v0, ncv=ncv, maxiter=max(300, 10 * N // ncv))
            return th, V, True
        except sla.ArpackNoConvergence as exc:
            th, V = exc.eigenvalues, exc.eigenvectors
    return th, V, False


# --------------------------------------------------------------------------------------------- residual bounds


def qep_residuals(M: Matrix, D: Matrix, K: Matrix, lam: np.ndarray, X: np.ndarray, Y: np.ndarray | None = None
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Residual norms and first-order error bounds of approximate eigentriplets of ``λ²M + λD + K``.

    Parameters
    ----------
    M, D, K : matrix
        The coefficient matrices (dense or sparse).
    lam : numpy.ndarray
        Approximate eigenvalues, shape ``(m,)``.
    X : numpy.ndarray
        Right vectors, shape ``(n, m)``.
    Y : numpy.ndarray, optional
        Left vectors (``y^H Q(λ) ≈ 0``), shape ``(n, m)``; without them the bounds are ``inf``.

    Returns
    -------
    residual : numpy.ndarray
        ``‖Q(λ)x‖ / ‖x‖``.
    bound : numpy.ndarray
        ``‖y‖ (‖Q(λ)x‖ + ρ) / |y^H (2λM + D) x|`` (module docstring), the first-order bound of the
        distance to the nearest exact eigenvalue.
    """
    lam = np.asarray(lam, dtype=complex)
    X = np.asarray(X, dtype=complex)
    MX, DX, KX = M @ X, D @ X, K @ X
    R = KX + DX * lam + MX * lam**2
    xn = np.linalg.norm(X, axis=0)
    rn = np.linalg.norm(R, axis=0)
    if Y is None:
        return rn / xn, np.full(lam.shape, np.inf)
    al = np.abs(lam)
    aX = np.abs(X)
    m = max(_row_nnz(A) for A in (M, D, K)) + 3
    gamma = m * _U / (1 - m * _U)
    rho = gamma * np.linalg.norm(abs(K) @ aX + (abs(D) @ aX) * al + (abs(M) @ aX) * al**2, axis=0)
    Y = np.asarray(Y, dtype=complex)
    dq = np.abs(np.einsum("ij,ij->j", Y.conj(), 2 * MX * lam + DX))
    with np.errstate(divide="ignore", invalid="ignore"):
        bound = np.where(dq > 0, np.linalg.norm(Y, axis=0) * (rn + rho) / dq, np.inf)
    return rn / xn, bound


def _row_nnz(A: Matrix) -> int:
    """Largest number of nonzeros in a row (the length of the dot products of a product ``A x``)."""
    if sp.issparse(A):
        return int(np.diff(sp.csr_matrix(A).indptr).max(initial=0))
    return int(np.asarray(A).shape[1])


def _refine(M: sp.csc_matrix, D: sp.csc_matrix, K: sp.csc_matrix, lam: complex, x: np.ndarray, y: np.ndarray
            ) -> complex:
    """Two-sided Rayleigh quotient: the root of ``y^H Q(μ) x = 0`` nearest ``lam``, if its residual is smaller."""
    a, b, c = (complex(np.vdot(y, A @ x)) for A in (M, D, K))
    if a == 0:
        return lam
    roots = np.roots([a, b, c])
    mu = complex(roots[np.argmin(np.abs(roots - lam))])

    def res(z: complex) -> float:
        return float(np.linalg.norm(K @ x + z * (D @ x) + z * z * (M @ x)))

    return mu if res(mu) < res(lam) else lam


def _polish(M: sp.csc_matrix, D: sp.csc_matrix, K: sp.csc_matrix, lam: complex, x: np.ndarray, y: np.ndarray,
            bound: float, steps: int = 3) -> tuple[complex, np.ndarray, float]:
    """Two-sided inverse iteration with the LU of ``Q(lam)``; returns the triplet with the smallest bound."""
    try:
        lu = sla.splu((K + lam * D + (lam * lam) * M).tocsc().astype(complex))
    except RuntimeError:  # Q(λ) exactly singular: λ is exact to working precision
        return lam, x, bound
    best = (lam, x, bound)
    for _ in range(steps):
        x = lu.solve(np.ascontiguousarray(x, dtype=complex))
        y = lu.solve(np.ascontiguousarray(y, dtype=complex), trans="H")
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
            break
        x, y = x / np.linalg.norm(x), y / np.linalg.norm(y)
        mu = _refine(M, D, K, best[0], x, y)
        if lam.imag == 0:
            mu = complex(mu.real, 0.0)
        b = float(qep_residuals(M, D, K, np.array([mu]), x[:, None], y[:, None])[1][0])
        if b < best[2]:
            best = (mu, x, b)
    return best


# --------------------------------------------------------------------------------------------- placement


def _covered(records: list[ShiftRecord], c: float, w: float, y_lo: float, y_hi: float) -> list[tuple[float, float]]:
    """Sub-intervals of ``[y_lo, y_hi]`` (Im λ) whose box strip is NOT inside a trusted disc."""
    spans = sorted((r.sigma.imag - math.sqrt(r.radius**2 - w**2) * (1 - _EDGE),
                    r.sigma.imag + math.sqrt(r.radius**2 - w**2) * (1 - _EDGE))
                   for r in records if r.radius > w)
    gaps, lo = [], y_lo
    for a, b in spans:
        if a > lo:
            gaps.append((lo, min(a, y_hi)))
        lo = max(lo, b)
        if lo >= y_hi:
            break
    if lo < y_hi:
        gaps.append((lo, y_hi))
    return [(a, b) for a, b in gaps if b > a]


def _next_shift(gap: tuple[float, float], h: float | None, c: float, last: complex | None) -> complex:
    """A shift for the lowest uncovered band ``gap`` (of Im λ).

    The first shift goes a quarter into the band (never onto the real axis, where the conjugate
    pairs are equidistant from ``σ`` and ARPACK converges slowly); after a disc too narrow for
    the box (``h = 0``) the same point is tried with a larger ``k``; otherwise the shift is put
    so that a disc like the last one (half-height ``h``) reaches the band's bottom with margin.
    """
    a, b = gap
    if h is None or last is None:
        return complex(c, a + 0.25 * (b - a))
    if h == 0:
        return last
    return complex(c, min(a + 0.8 * h, max(a + 0.5 * (b - a), b - 0.8 * h)))


# --------------------------------------------------------------------------------------------- main routine


def box_eigenvalues(M: Matrix, D: Matrix, K: Matrix, *, re: tuple[float, float], freq: tuple[float, float],
                    k: int = 60, tol: float = 1e-12, max_shifts: int = 40, vectors: bool = True, polish: bool = True,
                    progress: Callable[[int, int], Any] | None = None) -> BoxResult:
    r"""Eigenvalues of ``(λ²M + λD + K)x = 0`` in ``re_lo <= Re λ <= re_hi``, ``f_lo <= Im λ/2π <= f_hi``.

    Shift-and-invert Arnoldi on the companion pencil with adaptively placed shifts until the box
    is covered by trusted discs (module docstring), then residual-based error bounds from left
    and right eigenvectors and a stability verdict that is never silently wrong: when the box is
    not covered, runs disagree, or a bound straddles ``Re λ = 0``, the verdict is
    ``"undecided: ..."``.

    Parameters
    ----------
    M, D, K : numpy.ndarray or scipy.sparse matrix
        Real square coefficient matrices of equal size ``n`` (``M`` nonsingular in practice).
    re : (float, float)
        ``(re_lo, re_hi)`` of the box [1/s], finite, ``re_lo < re_hi``.  Only eigenvalues in the
        box are judged: ``re_hi`` must exceed the real parts of interest (e.g. a positive bound
        above any plausible growth rate) for "stable in box" to mean what it says.
    freq : (float, float)
        ``(f_lo, f_hi)`` [Hz] with ``0 <= f_lo < f_hi`` (``f = Im λ / 2π``).
    k : int
        Eigenvalues per shift (the Arnoldi subspace is ``2k + 1``).  Doubled (up to ``2n - 2``)
        for the next shift when a disc is too small to span the box's width.
    tol : float
        ARPACK's relative tolerance of the Ritz values.
    max_shifts : int
        At most this many shifts; if the box is not covered then, ``complete=False``.
    vectors : bool
        Whether to return the right eigenvectors.
    polish : bool
        Whether an eigenvalue whose bound straddles ``Re λ = 0`` is polished by inverse iteration
        with an LU of ``Q(λ)`` (module docstring) before it is declared undecided.
    progress : callable, optional
        ``progress(done, total)`` after each shift; ``total`` is the current estimate (the final
        call has ``done == total``).

    Returns
    -------
    BoxResult

    Raises
    ------
    ParameterError
        Non-square, mismatched, complex or non-finite matrices; an empty or invalid box; bad
        ``k``, ``tol`` or ``max_shifts``.
    """
    Ms, Ds, Ks = _as_matrix(M, "M"), _as_matrix(D, "D"), _as_matrix(K, "K")
    n = Ms.shape[0]
    for name, X in (("D", Ds), ("K", Ks)):
        if X.shape != Ms.shape:
            raise ParameterError(f"{name} has shape {X.shape}, M has {Ms.shape}: sizes must match", parameter=name)
    box = _check_box(re, freq)
    if not isinstance(k, (int, np.integer)) or k < 1:
        raise ParameterError(f"k = {k!r}: must be a positive integer", parameter="k")
    if not (isinstance(tol, (int, float)) and math.isfinite(tol) and 0 <= tol < 1):
        raise ParameterError(f"tol = {tol!r}: must be in [0, 1)", parameter="tol")
    if not isinstance(max_shifts, (int, np.integer)) or max_shifts < 1:
        raise ParameterError(f"max_shifts = {max_shifts!r}: must be a positive integer", parameter="max_shifts")
    if 2 * n < 4:
        raise ParameterError(f"n = {n}: the problem is too small for Arnoldi (use a dense solver)", parameter="M")

    re_lo, re_hi, f_lo, f_hi = box
    c, w = 0.5 * (re_lo + re_hi), 0.5 * (re_hi - re_lo)
    y_lo, y_hi = 2 * math.pi * f_lo, 2 * math.pi * f_hi
    kmax = 2 * n - 2
    kk = min(int(k), kmax)
    rng = np.random.default_rng(20160901)  # a fixed starting vector: reproducible results
    v0 = rng.standard_normal(2 * n) + 1j * rng.standard_normal(2 * n)

    records: list[ShiftRecord] = []
    runs: list[dict[str, Any]] = []
    notes: list[str] = []
    h_last: float | None = None
    while True:
        gaps = _covered(records, c, w, y_lo, y_hi)
        if not gaps or len(records) >= max_shifts:
            break
        sigma = _next_shift(gaps[0], h_last, c, records[-1].sigma if records else None)
        run = _one_shift(Ms, Ds, Ks, sigma, kk, tol, v0, runs[0]["permc"] if runs else None)
        runs.append(run)
        records.append(run["record"])
        r = run["record"].radius
        h_last = math.sqrt(r * r - w * w) if r > w else 0.0
        if r <= w:
            if kk >= kmax:
                notes.append(f"the disc of σ = {sigma:.6g} with k = {kk} does not span the box width {2 * w:g}")
                break
            kk = min(2 * kk, kmax)
        if progress is not None:
            rest = sum(b - a for a, b in _covered(records, c, w, y_lo, y_hi))
            est = len(records) + (math.ceil(rest / (1.6 * h_last)) if rest > 0 and h_last else 0)
            progress(len(records), min(max(est, len(records)), max_shifts))

    gaps = _covered(records, c, w, y_lo, y_hi)
    if gaps:
        band = ", ".join(f"{a / (2 * math.pi):.6g}–{b / (2 * math.pi):.6g} Hz" for a, b in gaps)
        notes.append(f"band {band} not covered by the trusted discs of {len(records)} shifts (max_shifts)")
    for run in runs:
        if not run["record"].converged:
            notes.append(f"Arnoldi at σ = {run['record'].sigma:.6g} did not converge")
    lam, X, Y, inconsistent = _collect(runs, box)
    if inconsistent:
        more = f" (+{len(inconsistent) - 3} more)" if len(inconsistent) > 3 else ""
        notes.append("; ".join(inconsistent[:3]) + more)

    ref = np.array([_refine(Ms, Ds, Ks, lam[i], X[:, i], Y[:, i]) if np.all(np.isfinite(Y[:, i])) else lam[i]
                    for i in range(lam.size)], dtype=complex)
    lam = np.where(lam.imag == 0, ref.real + 0j, ref)  # eigenvalues taken as real stay real
    Yb = np.where(np.isfinite(Y), Y, 0)
    _, bound = qep_residuals(Ms, Ds, Ks, lam, X, Yb)
    bound = np.where(np.all(np.isfinite(Y), axis=0), bound, np.inf)
    if polish:
        for i in np.flatnonzero((np.abs(lam.real) <= bound) & np.isfinite(bound)):
            lam[i], X[:, i], bound[i] = _polish(Ms, Ds, Ks, lam[i], X[:, i], Yb[:, i], bound[i])
    order = np.argsort(-lam.real, kind="stable")
    lam, bound, X, Y = lam[order], bound[order], X[:, order], Y[:, order]
    complete = not notes
    unstable = int(np.count_nonzero(lam.real - bound > 0))
    undecided = int(np.count_nonzero(np.abs(lam.real) <= bound))
    verdict = _verdict(lam, bound, complete, notes)
    if progress is not None:
        progress(len(records), len(records))
    return BoxResult(eigenvalues=lam, bounds=bound, vectors=X if vectors else None, box=box, complete=complete,
                     unstable=unstable, undecided=undecided, verdict=verdict,
                     shifts=tuple(r.sigma for r in records), records=tuple(records), notes=tuple(notes),
                     left_vectors=Y if vectors else None)


def _one_shift(M: sp.csc_matrix, D: sp.csc_matrix, K: sp.csc_matrix, sigma: complex, k: int, tol: float,
               v0: np.ndarray, permc: str | None) -> dict[str, Any]:
    """Right and left (transposed) shift-and-invert Arnoldi runs at ``sigma``."""
    n = M.shape[0]
    try:
        si = _ShiftInvert(M, D, K, sigma, permc)
    except RuntimeError:  # Q(σ) exactly singular: σ is an eigenvalue; move it a little
        sigma = sigma + complex(0, 1e-7 * max(1.0, abs(sigma)))
        si = _ShiftInvert(M, D, K, sigma, permc)
    th, V, ok = _arnoldi(si.operator(False), k, tol, v0)
    tht, Vt, okt = _arnoldi(si.operator(True), k, tol, v0)
    lam = sigma + 1.0 / th
    lamt = sigma + 1.0 / tht
    X = V[:n]
    X = X / np.linalg.norm(X, axis=0)
    Yc = Vt[:n].conj()  # left eigenvectors of Q: conj of the transposed problem's right ones
    Yc = Yc / np.linalg.norm(Yc, axis=0)
    radius = float(np.max(np.abs(lam - sigma))) if ok and lam.size == k else 0.0
    rec = ShiftRecord(sigma=sigma, radius=radius, k=k, eigenvalues=lam, converged=ok and okt)
    return {"record": rec, "lam": lam, "X": X, "lamt": lamt, "Y": Yc, "permc": si.permc}


def _match(p: complex, cands: np.ndarray) -> int:
    """Index of the candidate equal to ``p`` (relative ``_MATCH``), or -1."""
    if cands.size == 0:
        return -1
    d = np.abs(cands - p)
    i = int(np.argmin(d))
    return i if d[i] <= _MATCH * max(1.0, abs(p)) else -1


def _in_box(lam: np.ndarray, box: tuple[float, float, float, float], slack: np.ndarray) -> np.ndarray:
    """Which of ``lam`` lie in the box; with ``f_lo = 0`` an eigenvalue with ``Im λ >= -slack`` counts as real."""
    re_lo, re_hi, f_lo, f_hi = box
    im = lam.imag
    if f_lo == 0:  # a real eigenvalue comes out of Arnoldi with a tiny imaginary part of either sign
        im = np.where(np.abs(im) <= slack, 0.0, im)
    return (lam.real >= re_lo) & (lam.real <= re_hi) & (im >= 2 * math.pi * f_lo) & (im <= 2 * math.pi * f_hi)


def _collect(runs: list[dict[str, Any]], box: tuple[float, float, float, float]
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[str]]:
    """Deduplicate the runs' box eigenvalues; check overlapping discs and the left runs.

    Each eigenvalue found by several shifts is taken from the shift in whose disc it lies
    deepest (smallest ``|λ - σ|/r``); ties by shift order.  The comparison uses each run's own
    value of the matched pair, so that exactly one copy is kept.
    """
    lams, Xs, Ys, bad = [], [], [], []
    recs = [r["record"] for r in runs]
    for i, run in enumerate(runs):
        ri = recs[i]
        slack = _REAL * np.abs(run["lam"] - ri.sigma)
        for a in np.flatnonzero(_in_box(run["lam"], box, slack)):
            p = run["lam"][a]
            depth_i = abs(p - ri.sigma) / ri.radius if ri.radius > 0 else math.inf
            keep = True
            for j, rj in enumerate(recs):
                if j == i or rj.radius == 0:
                    continue
                b = _match(p, runs[j]["lam"])
                inside = abs(p - rj.sigma) < (1 - _EDGE) * rj.radius
                if b < 0:
                    if inside:
                        bad.append(f"λ = {p:.8g} found at σ = {ri.sigma:.6g} but not at σ = {rj.sigma:.6g}")
                    continue
                depth_j = abs(runs[j]["lam"][b] - rj.sigma) / rj.radius
                if (depth_j, j) < (depth_i, i):
                    keep = False
                    break
            if not keep:
                continue
            t = _match(p, run["lamt"])
            if t < 0:
                bad.append(f"λ = {p:.8g}: no left eigenvector (transposed run at σ = {ri.sigma:.6g})")
            if box[2] == 0 and abs(p.imag) <= slack[a]:
                p = complex(p.real, 0.0)
            lams.append(p)
            Xs.append(run["X"][:, a])
            Ys.append(run["Y"][:, t] if t >= 0 else np.full(run["X"].shape[0], np.nan, dtype=complex))
    n = runs[0]["X"].shape[0] if runs else 0
    lam = np.array(lams, dtype=complex)
    X = np.array(Xs, dtype=complex).T if Xs else np.zeros((n, 0), dtype=complex)
    Y = np.array(Ys, dtype=complex).T if Ys else np.zeros((n, 0), dtype=complex)
    return lam, X, Y, bad


def _verdict(lam: np.ndarray, bound: np.ndarray, complete: bool, notes: list[str]) -> str:
    """The one-line verdict (class docstring of :class:`BoxResult`)."""
    f = np.abs(lam.imag) / (2 * math.pi)
    unst = lam.real - bound > 0
    straddle = np.abs(lam.real) <= bound
    band = (f"[{f[unst].min():.6g}, {f[unst].max():.6g}] Hz" if unst.any() else "")
    modes = "mode" if int(unst.sum()) == 1 else "modes"
    if not complete:
        head = f"at least {int(unst.sum())} unstable {modes} in {band}; " if unst.any() else ""
        return "undecided: " + head + "; ".join(notes)
    if straddle.any():
        where = ", ".join(f"{v:.6g}" for v in f[straddle][:5])
        head = f"{int(unst.sum())} unstable {modes} in {band}; " if unst.any() else ""
        return (f"undecided: {head}{int(straddle.sum())} eigenvalues with |Re λ| within their error bound "
                f"at {where} Hz")
    if unst.any():
        return f"{int(unst.sum())} unstable {modes} in {band}"
    return "stable in box"
