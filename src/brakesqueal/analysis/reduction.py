r"""Parametric model reduction of a finite-element brake QEP by POD of sampled eigenvectors.

The method of Gräbner, Mehrmann, Quraishi, Schröder and von Wagner, "Numerical methods for
parametric model reduction in the simulation of disc brake squeal", ZAMM 96(12) (2016)
1388–1405 (Section 4): for the parametric problem

.. math::  \bigl(\lambda^2 M + \lambda D(\Omega) + K(\Omega)\bigr)x = 0,\qquad
           D(\Omega) = \textstyle\sum_i d_i(\Omega) D_i,\quad K(\Omega) = \sum_j k_j(\Omega) K_j,

1. compute the eigenvectors ``X(Ω_s)`` of the wanted eigenvalues (here: those in a box, by
   :func:`~brakesqueal.analysis.sparse_box.box_eigenvalues`) at sample speeds ``Ω_s``;
2. form the real snapshot matrix ``S = [Re X, Im X]`` of all samples (each eigenvector scaled to
   unit norm), a real basis keeping the problem real;
3. truncate its SVD ``S = U Σ W^T`` (POD): ``V = U[:, :r]``;
4. project every coefficient matrix, ``M_r = V^T M V``, ``D_{i,r} = V^T D_i V``,
   ``K_{j,r} = V^T K_j V`` (Galerkin), so that the reduced model keeps the parametric structure
   and is assembled for any ``Ω`` at the cost of ``r × r`` sums.

The reduced eigenvalues are those of the dense ``r``-dimensional QEP (:func:`dense_qep_eigenvalues`).

With ``left=True`` (the default of :func:`reduce_qep`) the snapshots also hold the *left*
eigenvectors ``y`` (``y^H Q(λ) = 0``, which the box route computes for its error bounds anyway).
The problem is not symmetric, so a Galerkin projection on the right eigenvectors alone errs in an
eigenvalue to first order in the distance of its eigenvector from the basis; when the basis also
holds the left eigenvector, the error is the product of the two distances (the two-sided Rayleigh
quotient ``y^H Q x``), while the projection stays one-sided (a two-sided ``W^T X V`` with ``W``
from the left vectors alone was tried: as accurate, but it made spurious eigenvalues with Re λ up
to 6e5 1/s, one inside the box).  Measured on the 4669-DOF brake (4 samples over 2π…8π, box
eigenvalues at 3π, 5π, 7π against the full model's, whose smallest growth rate is 8.6e-5 1/s):

======================  ======================  =========================
basis                   largest relative error  largest real-part error
======================  ======================  =========================
right, r = 200          9.9e-9                  7.7e-5 1/s
right + left, r = 200   4.5e-7                  2.0e-4 1/s
right + left, r = 280   1.6e-10                 5.8e-7 1/s
right + left, r = 320   4.6e-11                 5.9e-8 1/s
======================  ======================  =========================

and no spurious eigenvalue in either.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence, Union

import numpy as np
import scipy.linalg as sl
import scipy.sparse as sp

from ..errors import BrakesquealError, ParameterError
from .sparse_box import BoxResult, box_eigenvalues

__all__ = ["ReducedBasis", "pod_basis", "project", "reduce_qep", "dense_qep_eigenvalues"]

Matrix = Union[np.ndarray, sp.spmatrix, sp.sparray]


@dataclass(frozen=True)
class ReducedBasis:
    """A real orthonormal reduction basis from POD of eigenvector snapshots.

    Attributes
    ----------
    V : numpy.ndarray
        ``(n, r)`` real basis with orthonormal columns.
    singular_values : numpy.ndarray
        All singular values of the snapshot matrix ``[Re X, Im X]`` (descending); the first ``r``
        are kept.
    samples : numpy.ndarray
        The parameter samples (disk speeds ``Ω`` [rad/s]) the snapshots were taken at (empty when
        not given).
    """

    V: np.ndarray
    singular_values: np.ndarray
    samples: np.ndarray

    @property
    def r(self) -> int:
        """The reduced dimension."""
        return int(self.V.shape[1])


def pod_basis(snapshots: Sequence[np.ndarray], r: int | None = None, tol: float = 1e-10, *,
              samples: Sequence[float] | None = None) -> ReducedBasis:
    """Real POD basis of complex eigenvector snapshots (Gräbner et al. 2016, Sect. 4).

    Parameters
    ----------
    snapshots : sequence of numpy.ndarray
        Per sample an ``(n, m_s)`` (or ``(n,)``) array of eigenvectors; each column is scaled to
        unit 2-norm before the SVD (every mode weighs the same).
    r : int, optional
        Reduced dimension; default: every direction with ``σ_i > tol σ_1``.
    tol : float
        Relative singular-value cut-off when ``r`` is not given.
    samples : sequence of float, optional
        The parameter values of the snapshots (stored in the result).

    Returns
    -------
    ReducedBasis

    Raises
    ------
    ParameterError
        No snapshots, mismatched row counts, non-finite entries, a bad ``r`` or ``tol``.
    """
    cols = [np.asarray(S).reshape(np.shape(S)[0], -1) for S in snapshots]
    if not cols or sum(c.shape[1] for c in cols) == 0:
        raise ParameterError("snapshots: need at least one eigenvector", parameter="snapshots")
    n = cols[0].shape[0]
    if any(c.shape[0] != n for c in cols):
        raise ParameterError(f"snapshots: row counts {[c.shape[0] for c in cols]} differ", parameter="snapshots")
    X = np.concatenate(cols, axis=1).astype(complex)
    if not np.all(np.isfinite(X)):
        raise ParameterError("snapshots contain NaN or infinite entries", parameter="snapshots")
    norms = np.linalg.norm(X, axis=0)
    X = X[:, norms > 0] / norms[norms > 0]
    # (the phase of an eigenvector does not matter: span{Re x, Im x} and S S^T = Re(X X^H) are invariant)
    S = np.concatenate([X.real, X.imag], axis=1)
    U, sv, _ = sl.svd(S, full_matrices=False, lapack_driver="gesdd")
    if r is None:
        if not (math.isfinite(tol) and 0 < tol < 1):
            raise ParameterError(f"tol = {tol!r}: must be in (0, 1)", parameter="tol")
        r = int(np.count_nonzero(sv > tol * sv[0]))
    elif not isinstance(r, (int, np.integer)) or not 1 <= r <= sv.size:
        raise ParameterError(f"r = {r!r}: must be an integer in [1, {sv.size}] (the snapshot rank bound)",
                             parameter="r")
    smp = np.asarray([] if samples is None else list(samples), dtype=float)
    return ReducedBasis(V=np.ascontiguousarray(U[:, :r]), singular_values=sv, samples=smp)


def project(V: np.ndarray, matrices: Mapping[str, Matrix]) -> dict[str, np.ndarray]:
    """Galerkin projection ``V^T X V`` of every coefficient matrix (dense ``r × r`` outputs).

    Parameters
    ----------
    V : numpy.ndarray
        ``(n, r)`` real basis.
    matrices : mapping of str to matrix
        The coefficient matrices by name (dense or sparse, ``n × n``).

    Returns
    -------
    dict of str to numpy.ndarray

    Raises
    ------
    ParameterError
        A matrix whose shape does not match ``V``.
    """
    V = np.asarray(V)
    if V.ndim != 2:
        raise ParameterError(f"V must be 2-D, got shape {V.shape}", parameter="V")
    n = V.shape[0]
    out: dict[str, np.ndarray] = {}
    for name, X in matrices.items():
        if X.shape != (n, n):
            raise ParameterError(f"{name} has shape {X.shape}, the basis has {n} rows", parameter=name)
        XV = X @ V
        out[name] = np.asarray(V.T @ np.asarray(XV))
    return out


def dense_qep_eigenvalues(M: np.ndarray, D: np.ndarray, K: np.ndarray) -> np.ndarray:
    """All ``2r`` eigenvalues of a small dense QEP ``λ²M + λD + K``: QZ of the scaled companion pencil, the
    routine of :func:`~.linear.qep_eigenvalues` (what ``linearize`` lists for a matrix model).

    Parameters
    ----------
    M, D, K : numpy.ndarray
        ``r × r`` real matrices.

    Returns
    -------
    numpy.ndarray
        Complex eigenvalues (infinite ones where ``M`` is singular).
    """
    from .linear import qep_eigenvalues

    return qep_eigenvalues(np.asarray(M, dtype=float), np.asarray(D, dtype=float), np.asarray(K, dtype=float),
                           finite=False)


def reduce_qep(qep: Callable[[float], tuple[Matrix, Matrix, Matrix]], omegas: Sequence[float], *,
               re: tuple[float, float], freq: tuple[float, float], r: int | None = None, tol: float = 1e-10,
               k: int = 60, max_shifts: int = 40, require_complete: bool = True, left: bool = True,
               progress: Callable[[int, int], Any] | None = None) -> ReducedBasis:
    """POD basis of the box eigenvectors (right and, with ``left``, left) of a parametric QEP sampled at
    ``omegas``.

    Parameters
    ----------
    qep : callable
        ``qep(Omega) -> (M, D, K)`` at one disk speed.
    omegas : sequence of float
        The sample speeds (the paper samples the studied range, e.g. ``2π … 8π``).
    re, freq : (float, float)
        The box (see :func:`~brakesqueal.analysis.sparse_box.box_eigenvalues`); a box a little
        wider than the one the reduced model is used for keeps modes entering it.
    r, tol : int or None, float
        Reduced dimension or relative singular-value cut-off (:func:`pod_basis`).
    k, max_shifts : int
        Passed to :func:`~brakesqueal.analysis.sparse_box.box_eigenvalues`.
    require_complete : bool
        Raise if a sample's box result is not complete (its eigenvectors may miss a mode).
    left : bool
        Also the left eigenvectors in the snapshots (module docstring): eigenvalue errors of the
        product of the right and left vectors' distances from the basis instead of first order.
    progress : callable, optional
        ``progress(done, total)`` per sample.

    Returns
    -------
    ReducedBasis

    Raises
    ------
    ParameterError
        No samples or a non-finite sample.
    BrakesquealError
        A sample whose box analysis is incomplete while ``require_complete``.
    """
    om = [float(w) for w in omegas]
    if not om or not all(math.isfinite(w) for w in om):
        raise ParameterError(f"omegas = {omegas!r}: need at least one finite sample", parameter="omegas")
    snaps: list[np.ndarray] = []
    for i, w in enumerate(om):
        M, D, K = qep(w)
        res: BoxResult = box_eigenvalues(M, D, K, re=re, freq=freq, k=k, max_shifts=max_shifts, vectors=True)
        if require_complete and not res.complete:
            raise BrakesquealError(f"box analysis at Omega = {w:g} is incomplete ({res.verdict}); "
                                   "raise max_shifts or k, or pass require_complete=False")
        if res.vectors is not None and res.vectors.shape[1]:
            snaps.append(res.vectors)
        if left and res.left_vectors is not None:
            found = np.all(np.isfinite(res.left_vectors), axis=0)
            if np.any(found):
                snaps.append(res.left_vectors[:, found])
        if progress is not None:
            progress(i + 1, len(om))
    if not snaps:
        raise BrakesquealError(f"no eigenvalue in the box re={re}, freq={freq} at any sample")
    return pod_basis(snaps, r=r, tol=tol, samples=om)
