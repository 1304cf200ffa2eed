r"""Route ``charpoly-grid``: certified roots of the exact characteristic polynomial on a 2-D grid (any size).

Applies to a 2-D grid of a model whose zero state has rate-free pads that
provably touch and slide, when its silent motion is identically trivial on
the axes (:meth:`Engine.charpoly_table
<brakesqueal.codegen.engine.Engine.charpoly_table>`: ``det(λ²M + λD + K)`` as
an exact polynomial in ``λ`` and the two axes, rounded with radii).  The
roots are found by compiled Weierstrass sweeps warm-started along rows; the
verdict is read from the Gerschgorin disks of the generalized companion
matrix, which contain every root of every polynomial within the coefficient
bounds (:func:`~..kernels.charpoly_verdicts`).  Points whose disks do not
decide (or, with ``max_real`` wanted, do not give every root to
:data:`~..kernels.CHARPOLY_ACCURACY`) are passed on.
"""

from __future__ import annotations

import numpy as np

from ..kernels import charpoly_verdicts
from ._base import Context, Result, Route

__all__ = ["CharpolyGrid"]


class CharpolyGrid(Route):
    """See the module docstring."""

    name = "charpoly-grid"
    description = ("compiled: certified roots of the exact characteristic polynomial det(lam^2 M + lam D + K) "
                   "(Weierstrass/Gerschgorin inclusion disks, warm-started along rows)")

    def applies(self, ctx: Context) -> bool:
        pts = ctx.points
        if pts is None or pts.grid is None or ctx.engine is None or len(pts.grid.names) != 2:
            return False
        if ctx.engine.caps.closed_form and ctx.closed:
            return False  # the closed-form routes decide these exactly
        return self._table(ctx) is not None

    def _table(self, ctx: Context):  # type: ignore[no-untyped-def]
        assert ctx.points is not None and ctx.points.grid is not None and ctx.engine is not None
        if "charpoly-table" not in ctx.extra:
            outer, inner = ctx.points.grid.names
            ctx.extra["charpoly-table"] = ctx.engine.charpoly_table(ctx.points.space, outer, inner)
        return ctx.extra["charpoly-table"]

    def take(self, ctx: Context, pending: np.ndarray) -> np.ndarray:
        return pending[ctx.trivial[pending]]

    def run(self, ctx: Context, idx: np.ndarray) -> Result:
        assert ctx.points is not None and ctx.points.grid is not None
        grid = ctx.points.grid
        shape = grid.shape
        todo = np.zeros(int(np.prod(shape)), dtype=bool)
        todo[idx] = True
        codes, mr, fr = charpoly_verdicts(self._table(ctx), grid.values[0], grid.values[1], todo.reshape(shape),
                                          eigen=ctx.eigen)
        return Result(codes.reshape(-1)[idx], mr.reshape(-1)[idx], fr.reshape(-1)[idx])
