r"""Route ``extended``: extended-precision eigenvalues with componentwise error bounds (small systems).

Applies to linear systems of state size up to
:data:`~..robust.EXTENDED_VERDICT_MAX_SIZE`.  The double-precision bound of
:mod:`.eigen_bounds` is norm-wise: beside a massless pad's own mode of
``1e15``–``1e25`` (a tilted silent motion without normal dampers), or with
entries spanning ``1e100``, it is larger than the slow structural modes,
which stay undecided.  Here the pencil is taken as exact data with a relative
error per entry, its algebraic pad rows are eliminated and every finite
eigenvalue gets a first-order componentwise bound, in 40-digit arithmetic
(:func:`~..robust.extended_descriptor_verdict`; about 10 ms a point).
"""

from __future__ import annotations

import numpy as np

from ..robust import EXTENDED_VERDICT_MAX_SIZE, UNDECIDED, extended_analysis
from ._base import Context, Result, Route
from ._linear import linear_groups
from .eigen_bounds import excluded, state_labels

__all__ = ["Extended"]


class Extended(Route):
    """See the module docstring."""

    name = "extended"
    description = "40-digit eigenvalues of the linearization with componentwise error bounds"

    def applies(self, ctx: Context) -> bool:
        return True

    def run(self, ctx: Context, idx: np.ndarray) -> Result:
        res = Result.empty(idx.size)
        pos = {int(i): j for j, i in enumerate(idx)}
        for g in linear_groups(ctx, idx):
            E, A = g.descriptor()
            if E.shape[-1] > EXTENDED_VERDICT_MAX_SIZE:
                continue
            k = E.shape[-1] - 2 * g.n
            labels, skip = state_labels(ctx, g), excluded(ctx)
            for q, i in enumerate(g.idx):
                code, mr, fr, bd, lam, car = extended_analysis(E[q], A[q], k, labels, skip)
                if not lam.size:
                    code = UNDECIDED
                j = pos[int(i)]
                res.code[j], res.max_real[j], res.frequency[j], res.bound[j], res.carrier[j] = code, mr, fr, bd, car
        return res
