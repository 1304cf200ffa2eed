r"""Rigorous enclosures of polynomials over many boxes at once: the Taylor (centred) form in NumPy.

A box ``[m - r, m + r]`` (``m``, ``r`` doubles, the box inside it) and a
polynomial ``p(x) = Σ_β b_β x^β`` give ``p(m + r t) = Σ_α c_α t^α`` with
``c_α = Σ_β b_β Π_j C(β_j, α_j) m_j^(β_j-α_j) r_j^α_j`` for ``t ∈ [-1, 1]^k``;
the range of ``p`` over the box lies in ``c_0 ± Σ_{α≠0} |c_α|`` (one-sided for
``α`` with only even exponents).  The linear part is exact, so the excess
shrinks quadratically with the box.

Rounding: every ``c_α`` is a sum of products computed with at most ``L``
roundings each (powers, binomials, the contractions, the coefficient's own
rounding), so ``|fl(c_α) - c_α| <= γ_L Σ|products|`` whatever the summation
order (``γ_L = L u / (1 - L u)``); the same contraction with absolute values
bounds that sum.  Products that could underflow (their magnitude bound below
``2^-960``) or any non-finite value make the box's enclosure ``[-inf, inf]``.
"""

from __future__ import annotations

import math

import numpy as np

from ._table import PolyTable

__all__ = ["enclose", "taylor"]

_U = 2.0 ** -53


def _gamma(n: int) -> float:
    return n * _U / (1 - n * _U)


def _contract(X: np.ndarray, T: np.ndarray, axis: int) -> np.ndarray:
    """``X[n, ..., β_j, ...] T[n, β_j, α_j] -> [n, ..., α_j, ...]`` on tensor axis ``axis``."""
    Xm = np.moveaxis(X, axis, -1)
    shp = Xm.shape
    Y = np.matmul(Xm.reshape(shp[0], -1, shp[-1]), T)
    return np.moveaxis(Y.reshape(*shp[:-1], T.shape[-1]), -1, axis)


def taylor(table: PolyTable, m: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Taylor coefficients ``c_α`` of every polynomial about ``m`` scaled by ``r``, with error bounds.

    Parameters
    ----------
    table : PolyTable
        The polynomials.
    m, r : ndarray, shape (n, k)
        Centres and half-widths (``r >= 0``).

    Returns
    -------
    C : ndarray, shape (n, P, D_1, ..., D_k)
        Computed coefficients.
    err : ndarray, shape (n, P)
        Bound on ``Σ_α |fl(c_α) - c_α|`` (``inf`` where it cannot be given).
    ok : ndarray of bool, shape (n,)
        Every value finite and no product can underflow.
    """
    n, k = m.shape
    coef, rad = table.coef, table.rad
    degs = coef.shape[1:]
    X = np.broadcast_to(coef, (n, *coef.shape))
    A = np.broadcast_to(np.abs(coef) + rad, (n, *coef.shape))
    nz = np.abs(coef)[np.abs(coef) > 0]
    low = math.log2(float(nz.min())) if nz.size else 0.0
    lowb = np.full(n, low)
    L = 3
    with np.errstate(all="ignore"):
        for j in range(k):
            D = degs[j]
            e = np.arange(D)
            mp = np.ones((n, D))
            rp = np.ones((n, D))
            for i in range(1, D):
                mp[:, i] = mp[:, i - 1] * m[:, j]
                rp[:, i] = rp[:, i - 1] * r[:, j]
            beta, alpha = np.meshgrid(e, e, indexing="ij")
            valid = alpha <= beta
            binom = np.where(valid, np.vectorize(math.comb)(beta, np.where(valid, alpha, 0)), 0).astype(float)
            T = binom[None] * mp[:, np.where(valid, beta - alpha, 0)] * rp[:, alpha]
            T = np.where(valid[None], T, 0.0)
            aT = np.abs(T)
            # every nonzero partial product of the powers is at least min(1, |m|)^(D-1) min(1, r)^(D-1)
            am, ar = np.abs(m[:, j]), r[:, j]
            lowb = lowb + (D - 1) * (np.log2(np.minimum(1.0, np.where(am > 0, am, 1.0)))
                                     + np.log2(np.minimum(1.0, np.where(ar > 0, ar, 1.0))))
            X = _contract(X, T, j + 2)
            A = _contract(A, aT, j + 2)
            L += 3 * D + 1
        P = coef.shape[0]
        ok = np.all(np.isfinite(X.reshape(n, -1)), axis=1) & np.all(np.isfinite(A.reshape(n, -1)), axis=1)
        ok &= lowb > -960
        err = 2 * _gamma(L) * A.reshape(n, P, -1).sum(axis=2)
    err = np.where(ok[:, None], err, np.inf)
    return X, err, ok


def enclose(table: PolyTable, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                                       np.ndarray, np.ndarray, np.ndarray]:
    """Rigorous ranges of the table's polynomials over boxes and their values at the boxes' centres.

    Parameters
    ----------
    table : PolyTable
        The polynomials.
    lo, hi : ndarray, shape (n, k)
        Box bounds (``lo <= hi``).

    Returns
    -------
    low, high : ndarray, shape (n, P)
        Every value of each polynomial over the box lies in ``[low, high]``.
    mid : ndarray, shape (n, k)
        The centres (doubles inside the boxes).
    mlow, mhigh : ndarray, shape (n, P)
        Enclosures of each polynomial's value at ``mid``.
    smear : ndarray, shape (n, P, k)
        ``Σ_{α_j > 0} |c_α|``: how much of each enclosure's width dimension ``j`` causes (for choosing where
        to split).
    """
    n, k = lo.shape
    with np.errstate(all="ignore"):
        m = lo + (hi - lo) * 0.5
        m = np.minimum(np.maximum(m, lo), hi)
        r = np.maximum(hi - m, m - lo)
        r = np.nextafter(r, np.inf) * (r > 0)  # one ulp up: [m - r, m + r] covers the box
    C, err, ok = taylor(table, m, r)
    P = C.shape[1]
    flat = C.reshape(n, P, -1)
    degs = C.shape[2:]
    idx = np.indices(degs).reshape(k, -1)
    odd = np.any(idx % 2 == 1, axis=0)
    c0 = flat[:, :, 0]
    rest = flat[:, :, 1:]
    oddr = odd[1:]
    with np.errstate(all="ignore"):
        up = np.where(oddr, np.abs(rest), np.maximum(rest, 0.0)).sum(axis=2)
        dn = np.where(oddr, np.abs(rest), np.maximum(-rest, 0.0)).sum(axis=2)
        nterm = flat.shape[2] + 4
        slack = err + 4 * _gamma(nterm) * (np.abs(c0) + up + dn + err)
        low = c0 - dn - slack
        high = c0 + up + slack
        e0 = err + 4 * _gamma(4) * (np.abs(c0) + err)
        mlow = c0 - e0
        mhigh = c0 + e0
        smear = np.stack([np.abs(flat[:, :, idx[j] > 0]).sum(axis=2) for j in range(k)], axis=2)
    bad = ~(ok[:, None] & np.isfinite(low) & np.isfinite(high))
    low = np.where(bad, -np.inf, low)
    high = np.where(bad, np.inf, high)
    mlow = np.where(bad, -np.inf, mlow)
    mhigh = np.where(bad, np.inf, mhigh)
    return low, high, m, mlow, mhigh, smear
