r"""Route ``quartic-interval``: interval quartic of computed 2x2 matrices → certified Routh–Hurwitz.

Applies to second-order linear systems with two coordinates (no pad states
kept) built numerically (:mod:`._linear`): the quartic ``det(λ²M + λD + K)``
is formed in interval arithmetic from the entries with the norm-wise input
radii ``INPUT_REL · max|X|`` per matrix (:data:`~..robust.INPUT_REL`) and the
Routh array's signs are certified (:func:`~..robust.routh_verdicts`).
``max_real`` and the frequency come from the balanced companion matrix.
"""

from __future__ import annotations

import numpy as np

from ..robust import INPUT_REL, quartic_interval, roots_summary, routh_verdicts
from ._base import Context, Result, Route
from ._linear import linear_groups

__all__ = ["QuarticInterval"]


class QuarticInterval(Route):
    """See the module docstring."""

    name = "quartic-interval"
    description = "interval quartic of the linearization (norm-wise input radii), certified Routh-Hurwitz test"

    def applies(self, ctx: Context) -> bool:
        return ctx.engine is None or ctx.engine.caps.n == 2

    def run(self, ctx: Context, idx: np.ndarray) -> Result:
        res = Result.empty(idx.size)
        pos = {int(i): j for j, i in enumerate(idx)}
        for g in linear_groups(ctx, idx):
            if g.n != 2 or g.k != 0 or g.M is None or g.D is None or g.K is None:
                continue
            N = g.idx.size
            M, D, K = g.M, g.D, g.K
            E = np.concatenate([M.reshape(N, 4), D.reshape(N, 4), K.reshape(N, 4)], axis=1)
            with np.errstate(all="ignore"):
                R = np.concatenate([np.repeat(INPUT_REL * np.max(np.abs(X.reshape(N, 4)), axis=1, keepdims=True), 4,
                                              axis=1) for X in (M, D, K)], axis=1)
            A, RA = quartic_interval(E, R)
            code = routh_verdicts(A, RA)
            at = np.array([pos[int(i)] for i in g.idx], dtype=np.int64)
            res.code[at] = code
            if ctx.eigen:
                res.max_real[at], res.frequency[at] = roots_summary(A)
        return res
