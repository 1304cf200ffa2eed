"""The two design objectives, vectorised over candidate designs with common random numbers.

* :func:`squeal_counts` — squealing / decided draws per candidate (the certified verdict of
  :func:`brakesqueal.analysis.points.evaluate`, the one evaluator of maps, sweeps and ``brakesqueal uq``);
* :func:`certified_scales` — per candidate, the largest fraction of the uncertainty box (scaled about its centre)
  that the branch and bound of :func:`brakesqueal.robust.decide_boxes` certifies stable.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..status import DECIDED

if TYPE_CHECKING:
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace

__all__ = ["SampleCounts", "squeal_counts", "certified_scales", "design_box", "REL_WIDTH"]

#: Relative half-width of a design variable's side of a certified box when its tolerance is zero (the branch and
#: bound needs ``lo < hi``): a design is certified at its value to this relative accuracy.
REL_WIDTH = 1e-9


@dataclass
class SampleCounts:
    """Verdicts of the common draws at each candidate design.

    Attributes
    ----------
    squealing, decided : ndarray of int64, shape (S,)
        Draws with a certified unstable verdict / with any verdict.
    worst : ndarray, shape (S,)
        Largest ``max Re λ`` [1/s] over the decided draws (NaN where none).
    """

    squealing: np.ndarray
    decided: np.ndarray
    worst: np.ndarray


def squeal_counts(engine: Engine, space: ParameterSpace, X: Mapping[str, np.ndarray],
                  draws: Mapping[str, np.ndarray], *, block: int = 1 << 17) -> SampleCounts:
    """Certified verdicts of every draw at every candidate design (the same draws for each: common random numbers).

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The parameter space.
    X : Mapping[str, ndarray of shape (S,)]
        Design variable -> its value at each candidate.
    draws : Mapping[str, ndarray of shape (n,)]
        Uncertain parameter -> its draws.
    block : int
        Points evaluated at once.

    Returns
    -------
    SampleCounts
    """
    from ..analysis.points import evaluate

    S = len(next(iter(X.values())))
    n = len(next(iter(draws.values())))
    per = max(1, block // max(n, 1))
    sq = np.zeros(S, dtype=np.int64)
    dec = np.zeros(S, dtype=np.int64)
    worst = np.full(S, np.nan)
    codes = np.array([int(s) for s in DECIDED])
    for a in range(0, S, per):
        b = min(S, a + per)
        vals = {k: np.repeat(np.asarray(v[a:b], dtype=float), n) for k, v in X.items()}
        vals.update({k: np.tile(np.asarray(v, dtype=float), b - a) for k, v in draws.items()})
        v = evaluate(engine, space, vals)
        status = np.asarray(v.status).reshape(b - a, n)
        ok = np.isin(status, codes)
        stable = np.asarray(v.stable, dtype=bool).reshape(b - a, n)
        mr = np.asarray(v.max_real, dtype=float).reshape(b - a, n)
        sq[a:b] = (ok & ~stable).sum(axis=1)
        dec[a:b] = ok.sum(axis=1)
        good = ok & np.isfinite(mr)
        with np.errstate(invalid="ignore"):
            w = np.where(good, mr, -np.inf).max(axis=1)
        worst[a:b] = np.where(good.any(axis=1), w, np.nan)
    return SampleCounts(sq, dec, worst)


def design_box(x: Mapping[str, float], tolerance: float) -> dict[str, tuple[float, float]]:
    """The sides of a certified box for the design variables at ``x``: ``x (1 ± tolerance)`` (at least
    ``x (1 ± REL_WIDTH)``; an absolute ``REL_WIDTH`` at zero)."""
    out = {}
    for k, v in x.items():
        h = max(abs(v) * max(tolerance, REL_WIDTH), REL_WIDTH if v == 0 else 0.0)
        out[k] = (v - h, v + h)
    return out


def certified_scales(engine: Engine, space: ParameterSpace, X: Mapping[str, np.ndarray],
                     uncertain: Mapping[str, tuple[float, float]], tolerance: float, *, max_scale: float = 1.0,
                     levels: int = 8, steps: int = 8, max_boxes: int = 400) -> np.ndarray:
    """Per candidate, the largest scale ``t`` in ``[0, max_scale]`` for which the box

    ``centre ± t (hi - lo) / 2`` of every uncertain parameter, times the design tolerance box, is certified
    stable (0 where not even ``max_scale / (levels 2**steps)`` is); a box reaching invalid parameters (e.g. a
    negative friction coefficient) is not.

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The parameter space.
    X : Mapping[str, ndarray of shape (S,)]
        Design variable -> its value at each candidate.
    uncertain : Mapping[str, (lo, hi)]
        The uncertainty box (scale 1).
    tolerance : float
        Relative tolerance of the design variables (see :func:`design_box`).
    max_scale : float
        Largest scale tried.
    levels, steps : int
        Scales ``max_scale k / levels`` decided at once, then bisection steps between the last certified level and
        the next.
    max_boxes : int
        Branch-and-bound budget per decision (undecided counts as not certified).

    Returns
    -------
    ndarray of shape (S,)
        Certified scales (lower bounds of the true ones, to ``max_scale / (levels 2**steps)``).
    """
    from ..robust import decide_boxes

    names = (*X, *uncertain)
    xs = {k: np.asarray(v, dtype=float) for k, v in X.items()}
    S = len(next(iter(xs.values())))
    c = np.array([0.5 * (a + b) for a, b in uncertain.values()])
    h = np.array([0.5 * (b - a) for a, b in uncertain.values()])
    h_x = np.maximum(np.abs(np.stack(list(xs.values()), axis=1)) * max(tolerance, REL_WIDTH), REL_WIDTH)
    x_all = np.stack(list(xs.values()), axis=1)

    corners = np.array(list(itertools.product((0.0, 1.0), repeat=len(names))))

    def stable(t: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """Certified stable boxes at scale ``t[i]`` for candidate ``rows[i]`` (a box reaching invalid parameters at
        a corner or its centre is not)."""
        lo = np.concatenate([x_all[rows] - h_x[rows], c[None, :] - t[:, None] * h[None, :]], axis=1)
        hi = np.concatenate([x_all[rows] + h_x[rows], c[None, :] + t[:, None] * h[None, :]], axis=1)
        P = np.concatenate([lo[:, None, :] + corners[None, :, :] * (hi - lo)[:, None, :],
                            (0.5 * (lo + hi))[:, None, :]], axis=1)  # (R, corners + 1, k)
        flat = P.reshape(-1, len(names))
        ok = np.asarray(space.valid(space.arrays({n: flat[:, j] for j, n in enumerate(names)})), dtype=bool)
        valid = ok.reshape(P.shape[0], P.shape[1]).all(axis=1)
        out = np.zeros(lo.shape[0], dtype=bool)
        if valid.any():
            code = decide_boxes(engine, space, names, lo[valid], hi[valid], max_boxes=max_boxes).code
            out[valid] = np.asarray(code) == 1
        return out

    ks = np.arange(1, levels + 1)
    t = np.tile(ks * max_scale / levels, S)
    rows = np.repeat(np.arange(S), levels)
    ok = stable(t, rows).reshape(S, levels)
    prefix = np.cumprod(ok, axis=1).sum(axis=1)  # certified levels before the first that is not
    lo_t = prefix * max_scale / levels
    hi_t = np.minimum(lo_t + max_scale / levels, max_scale)
    todo = np.flatnonzero(prefix < levels)
    for _ in range(steps):
        if not todo.size:
            break
        mid = 0.5 * (lo_t[todo] + hi_t[todo])
        s = stable(mid, todo)
        lo_t[todo[s]] = mid[s]
        hi_t[todo[~s]] = mid[~s]
    return lo_t
