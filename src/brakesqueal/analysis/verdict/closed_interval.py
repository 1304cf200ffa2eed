r"""Route ``closed-interval``: bounded closed-form entries → interval quartic → certified Routh–Hurwitz.

Applies to trivial silent motions of a model with a closed form.  The
entries of ``Mbar, Dbar, Kbar`` are evaluated from the parameter vector with
a rigorous rounding bound each (:func:`~..kernels.trivial_entries`), the
quartic's coefficients in midpoint-radius interval arithmetic
(:func:`~..robust.quartic_interval`) and the Routh array with its signs
certified (:func:`~..robust.routh_verdicts`).  ``max_real`` and the frequency
come from the balanced companion matrix of the same quartic
(:func:`~..robust.roots_summary`).
"""

from __future__ import annotations

import numpy as np

from ..kernels import trivial_entries
from ..robust import quartic_interval, roots_summary, routh_verdicts
from ._base import ClosedFormRoute, Context, Result

__all__ = ["ClosedInterval"]


class ClosedInterval(ClosedFormRoute):
    """See the module docstring."""

    name = "closed-interval"
    description = "closed form: bounded entries, interval quartic, certified Routh-Hurwitz test"

    def run(self, ctx: Context, idx: np.ndarray) -> Result:
        assert ctx.points is not None and ctx.engine is not None
        P = ctx.points.rows(idx)
        E, R = trivial_entries(ctx.engine, P)
        A, RA = quartic_interval(E, R)
        code = routh_verdicts(A, RA)
        if ctx.eigen:
            mr, fr = roots_summary(A)
        else:
            mr = fr = np.full(idx.size, np.nan)
        return Result(code, mr, fr)
