"""Per-mode outputs of a UQ study: the real part and the frequency of every tracked mode at every design point.

The eigenvalues come from the linear systems the verdict dispatcher builds for a batch of points
(:func:`brakesqueal.analysis.verdict.point_eigenvalues`: the batched zero-state Jacobians of trivial silent
motions, the compiled Jacobian at non-trivial ones, an imported model's matrices), one batched eigenvalue
computation per batch: no per-point Python.

Tracking rule (documented in ``docs/uq.md``): a *mode* is an eigenvalue pair with ``Im λ > 0``; at every
point the modes are numbered by ascending frequency (mode 1 the lowest).  The number of modes is the one
most points have; a point with another number of oscillating modes (two modes turned overdamped, say) has
no per-mode values (NaN: its row is left out of the per-mode indices only).  Numbering by frequency is
reliable where the modes' frequency ranges over the inputs' support do not overlap, as for the two disk
modes of the paper's 2-DOF model; where they cross, the indices describe "the lowest-frequency mode", not a
mode followed by continuity (the study reports each mode's frequency range so an overlap can be seen).
"""

from __future__ import annotations

import numpy as np

__all__ = ["mode_eigenvalues", "track_modes"]


def mode_eigenvalues(spec: object, coords: dict[str, np.ndarray]) -> np.ndarray:
    """Every eigenvalue of the linear system at each sampled point (NaN rows where there is none).

    Parameters
    ----------
    spec : brakesqueal.sweep.compute.ChunkSpec
        The study (a sample study).
    coords : dict
        The sampled names' values (1-D arrays of equal length).

    Returns
    -------
    ndarray of complex, shape (points, m)
        Per point, the eigenvalues of its state matrix (``E^-1 A``; ``m`` the largest state size, shorter
        systems padded with NaN); a row of NaN where the point has no silent motion, invalid parameters or an
        unusable system.
    """
    from ..analysis.verdict import Points, point_eigenvalues
    from ..sweep.compute import build_space, engine_of

    sp = spec  # a ChunkSpec (typed loosely: brakesqueal.sweep is imported lazily)
    space = build_space(sp.preset, sp.values, sp.tied, sp.model)  # type: ignore[attr-defined]
    names = tuple(sp.names)  # type: ignore[attr-defined]
    axes = {n: np.asarray(coords[n], dtype=float).reshape(-1) for n in names}
    return point_eigenvalues(engine_of(space), space, Points(space, space.arrays(axes), names, settable=axes))


def track_modes(lam: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Real parts and frequencies of the tracked modes (see the module docstring for the rule).

    Parameters
    ----------
    lam : ndarray of complex, shape (points, m)
        Per point its eigenvalues (:func:`mode_eigenvalues`; NaN: none).

    Returns
    -------
    real, frequency : ndarray, shape (points, modes)
        ``Re λ`` [1/s] and ``Im λ / 2π`` [Hz] of the modes numbered by ascending frequency; NaN at points
        without eigenvalues or with another number of oscillating modes.
    """
    lam = np.asarray(lam, dtype=complex).reshape(len(lam), -1)
    n = lam.shape[0]
    has = np.any(np.isfinite(lam), axis=1)
    with np.errstate(invalid="ignore"):
        up = np.isfinite(lam) & (lam.imag > 0)
    counts = np.where(has, up.sum(axis=1), -1)
    k = int(np.bincount(counts[has]).argmax()) if has.any() else 0
    re = np.full((n, k), np.nan)
    fr = np.full((n, k), np.nan)
    sel = np.flatnonzero(counts == k)
    if k == 0 or sel.size == 0:
        return re, fr
    key = np.where(up[sel], lam[sel].imag, np.inf)
    order = np.argsort(key, axis=1, kind="stable")[:, :k]
    top = np.take_along_axis(lam[sel], order, axis=1)
    re[sel] = top.real
    fr[sel] = top.imag / (2 * np.pi)
    return re, fr
