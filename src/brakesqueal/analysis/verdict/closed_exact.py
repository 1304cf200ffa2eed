r"""Route ``closed-exact``: the closed form evaluated in exact rational arithmetic, exact Routh–Hurwitz.

Applies to trivial silent motions of a model with a closed form.  The
entries are evaluated exactly at the parameter vector (each float taken as
the binary rational it is; :meth:`Engine.exact_entries
<brakesqueal.codegen.engine.Engine.exact_entries>`), the quartic formed in
:class:`fractions.Fraction` arithmetic and the Routh array decided exactly
(:func:`~..robust.routh_exact`): every point not exactly on the stability
boundary is decided.  ``max_real`` and the frequency come from 50-digit roots
of the exact quartic (:func:`~..robust.mp_roots_summary`).  A few milliseconds
per point: the routes before it decide all but the points closest to the
boundary.
"""

from __future__ import annotations

import numpy as np

from ..robust import _exact_point
from ._base import UNDECIDED, ClosedFormRoute, Context, Result

__all__ = ["ClosedExact"]


class ClosedExact(ClosedFormRoute):
    """See the module docstring."""

    name = "closed-exact"
    description = "closed form: exact rational evaluation, exact Routh-Hurwitz test"

    def run(self, ctx: Context, idx: np.ndarray) -> Result:
        assert ctx.points is not None and ctx.engine is not None
        P = ctx.points.rows(idx)
        res = Result.empty(idx.size)
        for j in range(idx.size):
            if not np.all(np.isfinite(P[j])):
                continue
            c, m, f = _exact_point(ctx.engine, P[j], ctx.eigen)
            res.code[j], res.max_real[j], res.frequency[j] = c, m, f
        res.code[~np.isin(res.code, (0, 1))] = UNDECIDED
        return res
