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
from .eigen_bounds import pencil_route

__all__ = ["Extended"]


class Extended(Route):
    """See the module docstring."""

    name = "extended"
    description = "40-digit eigenvalues of the linearization with componentwise error bounds"

    def applies(self, ctx: Context) -> bool:
        return True

    def run(self, ctx: Context, idx: np.ndarray) -> Result:
        return pencil_route(ctx, idx, EXTENDED_VERDICT_MAX_SIZE, _verdict)


def _verdict(E: np.ndarray, A: np.ndarray, k: int, labels: np.ndarray, skip: np.ndarray | None
             ) -> tuple[int, float, float, float, int]:
    """:func:`~..robust.extended_analysis` of one pencil; undecided without a finite eigenvalue."""
    code, mr, fr, bd, lam, car = extended_analysis(E, A, k, labels, skip)
    if not lam.size:
        code = UNDECIDED
    return code, mr, fr, bd, car
