r"""Branch and bound on boxes: certified Liénard–Chipart signs over sub-boxes, certified-unstable centres.

A sub-box is *stable* when, over all of it, ``Den`` has one sign, ``N_4``
has one sign ``s`` and ``s N_0 .. s N_3`` and ``s H3`` are positive (the
quartic ``Σ N_i λ^i = Den Σ a_i λ^i`` is then Hurwitz at every point: all
coefficients of one sign and the third Hurwitz determinant ``Δ3(sN) = s H3``
positive).  Its centre is a *witness* when ``Den`` and ``N_4`` are nonzero
there and some ``s N_i`` or ``s H3`` is certified negative (a coefficient of
the wrong sign or a negative Hurwitz determinant: a root in the closed right
half-plane).  Anything else is split in two across its widest dimension
(relative to the root box) until the root's budget of boxes or the depth
limit is used up; what is left is *undecided*.  Many root boxes are decided
together, breadth first, in vectorised chunks.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._enclose import enclose
from ._table import PolyTable

__all__ = ["BoxOutcome", "branch_and_bound", "CHUNK"]

#: Boxes enclosed per vectorised call (bounds the memory of the Taylor tensors).
CHUNK = 4096

_DEN, _N4, _H3 = 0, 5, 6
_N03 = [1, 2, 3, 4]


@dataclass
class BoxOutcome:
    """What the branch and bound found for each root box.

    Attributes
    ----------
    code : ndarray of uint8, shape (R,)
        1 stable over the whole box, 0 a certified-unstable witness found, 2 undecided.
    witness : ndarray, shape (R, k)
        The witness (NaN where none).
    examined : ndarray of int64, shape (R,)
        Sub-boxes enclosed per root.
    stable_boxes : ndarray of int64, shape (R,)
        Sub-boxes certified stable per root.
    undecided : list of (int, ndarray, ndarray)
        ``(root, lo, hi)`` of each sub-box left undecided.
    """

    code: np.ndarray
    witness: np.ndarray
    examined: np.ndarray
    stable_boxes: np.ndarray
    undecided: list[tuple[int, np.ndarray, np.ndarray]]


def _classify(low: np.ndarray, high: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(stable, unstable)`` masks of enclosures ``[low, high]`` of the table's polynomials."""
    den = (low[:, _DEN] > 0) | (high[:, _DEN] < 0)
    pos = den & (low[:, _N4] > 0)
    neg = den & (high[:, _N4] < 0)
    stable = (pos & np.all(low[:, _N03] > 0, axis=1) & (low[:, _H3] > 0)) | \
             (neg & np.all(high[:, _N03] < 0, axis=1) & (high[:, _H3] < 0))
    unstable = (pos & (np.any(high[:, _N03] < 0, axis=1) | (high[:, _H3] < 0))) | \
               (neg & (np.any(low[:, _N03] > 0, axis=1) | (low[:, _H3] > 0)))
    return stable, unstable


def _split_score(low: np.ndarray, high: np.ndarray, mlow: np.ndarray, mhigh: np.ndarray,
                 smear: np.ndarray) -> np.ndarray:
    """Per dimension: Σ over polynomials whose sign the enclosure leaves open of the dimension's share of the
    width, relative to the value at the centre (the dimension that most hides a sign)."""
    with np.errstate(all="ignore"):
        open_ = (low <= 0) & (high >= 0)
        c0 = np.maximum(np.abs(0.5 * (mlow + mhigh)), np.finfo(float).tiny)
        return np.sum(np.where(open_[:, :, None], smear / c0[:, :, None], 0.0), axis=1)


def branch_and_bound(table: PolyTable, lo: np.ndarray, hi: np.ndarray, *, max_boxes: int = 2000,
                     max_depth: int = 60) -> BoxOutcome:
    """Decide root boxes ``[lo[i], hi[i]]`` (see the module docstring).

    Parameters
    ----------
    table : PolyTable
        The polynomials of the space.
    lo, hi : ndarray, shape (R, k)
        Root boxes (``lo < hi`` element-wise, finite).
    max_boxes : int
        Budget of sub-boxes per root box.
    max_depth : int
        Bisections of a sub-box at most.

    Returns
    -------
    BoxOutcome
    """
    lo = np.asarray(lo, dtype=float)
    hi = np.asarray(hi, dtype=float)
    R, k = lo.shape
    width0 = hi - lo
    code = np.full(R, 2, dtype=np.uint8)
    witness = np.full((R, k), np.nan)
    examined = np.zeros(R, dtype=np.int64)
    stable_boxes = np.zeros(R, dtype=np.int64)
    allocated = np.ones(R, dtype=np.int64)
    found = np.zeros(R, dtype=bool)
    undecided: list[tuple[int, np.ndarray, np.ndarray]] = []
    q_root = np.arange(R)
    q_lo, q_hi = lo.copy(), hi.copy()
    q_depth = np.zeros(R, dtype=np.int64)
    while q_root.size:
        keep = ~found[q_root]
        q_root, q_lo, q_hi, q_depth = q_root[keep], q_lo[keep], q_hi[keep], q_depth[keep]
        if not q_root.size:
            break
        n = q_root.size
        st = np.empty(n, dtype=bool)
        un = np.empty(n, dtype=bool)
        mun = np.empty(n, dtype=bool)
        mid = np.empty((n, k))
        score = np.empty((n, k))
        chunk = max(1, min(CHUNK, int(4e6 // table.coef.size)))  # the Taylor tensors stay within ~100 MB
        for a in range(0, n, chunk):
            b = min(n, a + chunk)
            low, high, m, mlow, mhigh, smear = enclose(table, q_lo[a:b], q_hi[a:b])
            st[a:b], un[a:b] = _classify(low, high)
            mun[a:b] = _classify(mlow, mhigh)[1]
            mid[a:b] = m
            score[a:b] = _split_score(low, high, mlow, mhigh, smear)
        np.add.at(examined, q_root, 1)
        np.add.at(stable_boxes, q_root[st], 1)
        wit = ~st & (un | mun)
        for i in np.flatnonzero(wit):
            r = q_root[i]
            if not found[r]:
                found[r] = True
                witness[r] = mid[i]
        rest = np.flatnonzero(~st & ~wit & ~found[q_root])
        if not rest.size:
            break
        # split where the undecided signs' enclosures are widest (else the widest dimension relative to the
        # root box) at the centre, within the budgets
        rl, rh, rr, rd, rm = q_lo[rest], q_hi[rest], q_root[rest], q_depth[rest], mid[rest]
        with np.errstate(all="ignore"):
            rel = np.where(width0[rr] > 0, (rh - rl) / width0[rr], 0.0)
        sc = score[rest]
        usable = np.all(np.isfinite(sc), axis=1) & (np.max(sc, axis=1) > 0)
        j = np.where(usable, np.argmax(np.where(np.isfinite(sc), sc, 0.0), axis=1), np.argmax(rel, axis=1))
        at = rm[np.arange(rest.size), j]
        ok = (rd < max_depth) & (at > rl[np.arange(rest.size), j]) & (at < rh[np.arange(rest.size), j])
        for i in np.flatnonzero(ok):  # budgets in queue order (breadth first)
            if allocated[rr[i]] + 2 > max_boxes:
                ok[i] = False
            else:
                allocated[rr[i]] += 2
        for i in np.flatnonzero(~ok):
            undecided.append((int(rr[i]), rl[i].copy(), rh[i].copy()))
        s = np.flatnonzero(ok)
        left_hi = rh[s].copy()
        left_hi[np.arange(s.size), j[s]] = at[s]
        right_lo = rl[s].copy()
        right_lo[np.arange(s.size), j[s]] = at[s]
        q_root = np.concatenate([rr[s], rr[s]])
        q_lo = np.concatenate([rl[s], right_lo])
        q_hi = np.concatenate([left_hi, rh[s]])
        q_depth = np.concatenate([rd[s] + 1, rd[s] + 1])
    code[found] = 0
    has_undecided = np.zeros(R, dtype=bool)
    for r, _, _ in undecided:
        has_undecided[r] = True
    code[~found & ~has_undecided] = 1
    undecided = [u for u in undecided if not found[u[0]]]
    return BoxOutcome(code, witness, examined, stable_boxes, undecided)
