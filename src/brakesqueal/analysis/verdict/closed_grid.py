r"""Route ``closed-grid``: the certified compiled Hurwitz kernel of a grid (closed form, trivial silent motion).

Applies to a full grid of a model with a closed form
(:attr:`Capabilities.closed_form <brakesqueal.codegen.engine.Capabilities.closed_form>`)
whose silent motion is trivial on the whole grid (:meth:`Engine.closed_route
<brakesqueal.codegen.engine.Engine.closed_route>`).  The exact numerators of
the quartic ``det(λ²M + λD + K)`` are polynomials in the grid's inner axis
with coefficients monomial in the other axes (:meth:`Engine.grid_kernel
<brakesqueal.codegen.engine.Engine.grid_kernel>`); each row's coefficients
are evaluated in exponent-scaled floating point with a rigorous error bound
and the compiled Liénard–Chipart test classifies every point stable,
unstable or uncertain.  ``max_real`` and the frequency come from the compiled
roots of the same quartic (:func:`~..kernels.kernel_eigen`); a point whose
roots were not found cleanly, or whose ``max_real`` contradicts its verdict,
is passed on.
"""

from __future__ import annotations

import numpy as np

from ..kernels import kernel_eigen, kernel_scaling, kernel_segments
from ._base import UNDECIDED, Context, Result, Route

__all__ = ["ClosedGrid"]


class ClosedGrid(Route):
    """See the module docstring."""

    name = "closed-grid"
    description = "closed form: certified compiled Hurwitz kernel of the exact quartic on the grid"

    def applies(self, ctx: Context) -> bool:
        pts = ctx.points
        if pts is None or pts.grid is None or ctx.engine is None or not ctx.closed:
            return False
        return self._kernel(ctx) is not None

    def _kernel(self, ctx: Context) -> tuple | None:  # type: ignore[type-arg]
        assert ctx.points is not None and ctx.points.grid is not None and ctx.engine is not None
        key = "closed-grid-kernel"
        if key not in ctx.extra:
            grid = ctx.points.grid
            kern = ctx.engine.grid_kernel(ctx.points.space, grid.names)
            scaled = None if kern is None else kernel_scaling(kern, grid.values[kern.inner])
            ctx.extra[key] = None if scaled is None else (kern, scaled)
        return ctx.extra[key]  # type: ignore[no-any-return]

    def take(self, ctx: Context, pending: np.ndarray) -> np.ndarray:
        return pending[ctx.trivial[pending]]

    def run(self, ctx: Context, idx: np.ndarray) -> Result:
        assert ctx.points is not None and ctx.points.grid is not None
        kern, (e, t) = self._kernel(ctx)  # type: ignore[misc]
        grid = ctx.points.grid
        shape = grid.shape
        i = kern.inner
        others = [k for k in range(len(shape)) if k != i]
        mesh = np.meshgrid(*[np.asarray(grid.values[k], dtype=float) for k in others], indexing="ij")
        outer = [m.ravel() for m in mesh]
        C, EC, lam_e = kern.row_tables(outer, e)
        t = np.ascontiguousarray(t, dtype=float)
        seg, T = kernel_segments(t)
        codes = np.empty((C.shape[0], t.size), dtype=np.uint8)
        kern.classify(C, EC, t, seg, T, codes)
        back = [shape[k] for k in others] + [shape[i]]

        def to_grid(a: np.ndarray) -> np.ndarray:
            return np.moveaxis(a.reshape(back), -1, i).reshape(-1)

        code = to_grid(codes)[idx]
        if ctx.eigen:
            mr, fr, ok = kernel_eigen(kern, C, t, lam_e)
            mr, fr, ok = to_grid(mr)[idx], to_grid(fr)[idx], to_grid(ok)[idx]
            code = np.where(ok.view(bool), code, UNDECIDED).astype(np.uint8)
        else:
            mr = fr = np.full(idx.size, np.nan)
        return Result(code, mr, fr)
