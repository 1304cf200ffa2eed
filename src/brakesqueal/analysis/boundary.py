r"""The stability boundary of a map as curves located to the solver's precision.

A map's verdicts live on a grid, so a contour of them is a staircase at the
grid's resolution.  :func:`stability_boundary` first traces the level ``1/2``
of the certified verdict field (``contourpy``, the contour engine of
matplotlib; every vertex lies on a grid edge whose two end points have
opposite verdicts) and then moves every vertex along its edge onto the
boundary by bisection with the same per-point evaluator the map used
(:func:`~.points.evaluate`).  After ``iterations`` halvings the bracket is
``2^-iterations`` of a grid step wide (the default, 40, gives 1e-12 of a
step), so the curve's points lie on the stability boundary far below the
resolution of any figure.  Points whose status is not decided
(invalid parameters, no silent motion, undecided) are holes of the field:
the curves stop at them.

Log axes are refined in ``log10`` of the parameter, so the bracket's relative
width is the same along the whole axis.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..status import PointStatus

__all__ = ["Boundary", "stability_boundary"]

_DECIDED = (int(PointStatus.OK), int(PointStatus.OK_NONTRIVIAL))


@dataclass(frozen=True)
class Boundary:
    """Stability-boundary curves of a two-parameter map.

    Attributes
    ----------
    names : tuple of str
        The two parameters ``(outer, inner)`` (the map's dimension order).
    coords : tuple of ndarray
        Vertex coordinates of both parameters (SI units), curves separated by NaN.
    refined : ndarray of bool
        Per vertex, whether it was moved onto the boundary (``False``: the
        midpoint of its grid edge, where an end of the edge is not decided);
        NaN separators are ``False``.
    width : ndarray
        Per vertex, the final bracket width relative to the grid step along the refined axis.
    """

    names: tuple[str, str]
    coords: tuple[np.ndarray, np.ndarray]
    refined: np.ndarray
    width: np.ndarray

    @property
    def vertices(self) -> int:
        """Number of vertices (separators excluded)."""
        return int(np.count_nonzero(np.isfinite(self.coords[0])))

    def curves(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """The curves as ``(outer values, inner values)`` pairs (split at the NaN separators)."""
        a, b = self.coords
        cut = np.flatnonzero(~np.isfinite(a))
        out, start = [], 0
        for c in [*cut.tolist(), a.size]:
            if c > start:
                out.append((a[start:c], b[start:c]))
            start = c + 1
        return out


def _t(v: np.ndarray, log: bool) -> np.ndarray:
    return np.log10(v) if log else np.asarray(v, dtype=float)


def _v(t: np.ndarray, log: bool) -> np.ndarray:
    return 10.0 ** t if log else t


def _nearest(grid: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Index of the nearest grid value to every ``v`` and the distance to it."""
    j = np.clip(np.searchsorted(grid, v), 1, grid.size - 1)
    left = np.abs(v - grid[j - 1]) <= np.abs(grid[j] - v)
    k = np.where(left, j - 1, j)
    return k, np.abs(v - grid[k])


def stability_boundary(space: Any, outer: Any, inner: Any, stable: np.ndarray, status: np.ndarray, *,
                       iterations: int = 40, budget: float | None = None,
                       evaluator: Callable[[dict[str, np.ndarray]], Any]) -> Boundary:
    """Stability boundary of a map, refined onto the boundary by bisection along grid edges.

    Parameters
    ----------
    space : ParameterSpace
        The map's parameter space.
    outer, inner : Axis
        The map's axes (``stable`` has shape ``(outer.num, inner.num)``).
    stable : ndarray of bool
        Certified verdicts of the map.
    status : ndarray of int
        :class:`~brakesqueal.status.PointStatus` codes of the map.
    iterations : int
        Bisection steps per vertex, in ``[0, 60]`` (0: no refinement).
    budget : float, optional
        Wall-time budget [s] of the refinement; when it runs out, the
        bisection stops and every vertex keeps its current bracket (its
        ``width`` says how far it got).  The default, no budget, keeps the
        result independent of the machine's speed.
    evaluator : callable
        ``evaluator({outer: values, inner: values}) -> Verdicts`` for the bisection
        points (maps pass :func:`~.points.evaluate` with their engine: the dispatcher's certified verdicts).

    Returns
    -------
    Boundary

    Raises
    ------
    ParameterError
        If ``iterations`` or ``budget`` is out of range, or the arrays do not match the axes.
    """
    from contourpy import contour_generator

    from ..errors import ParameterError

    if not (isinstance(iterations, (int, np.integer)) and 0 <= iterations <= 60):
        raise ParameterError(f"stability_boundary: 'iterations' must be an integer in [0, 60]; got {iterations!r}")
    if budget is not None and not (math.isfinite(budget) and budget > 0):
        raise ParameterError(f"stability_boundary: 'budget' must be positive [s]; got {budget!r}")
    stable = np.asarray(stable)
    status = np.asarray(status)
    shape = (outer.num, inner.num)
    if stable.shape != shape or status.shape != shape:
        raise ParameterError(f"stability_boundary: arrays must have the axes' shape {shape}; got {stable.shape}")
    names = (outer.name, inner.name)
    to = _t(outer.values(), outer.log)
    ti = _t(inner.values(), inner.log)
    decided = np.isin(status, _DECIDED)
    z = np.where(decided, stable.astype(float), np.nan)
    empty = Boundary(names, (np.empty(0), np.empty(0)), np.empty(0, bool), np.empty(0))
    if not (np.any(z == 0.0) and np.any(z == 1.0)):
        return empty
    gen = contour_generator(ti, to, np.ma.masked_invalid(z), name="serial", line_type="Separate")
    lines = [ln for ln in gen.lines(0.5) if len(ln) >= 2]
    if not lines:
        return empty
    pts: np.ndarray = np.concatenate([np.asarray(ln, dtype=float) for ln in lines])  # columns: inner, outer
    # the edge of every vertex: on a grid line of one axis, between two neighbours of the other
    ni_near, di = _nearest(ti, pts[:, 0])
    no_near, do = _nearest(to, pts[:, 1])
    # a vertex on a line inner = const (closer to it than to any line outer = const) varies along outer
    along_outer = di / max(np.ptp(ti), 1e-300) <= do / max(np.ptp(to), 1e-300)
    lo_o = np.clip(np.searchsorted(to, pts[:, 1]) - 1, 0, to.size - 2)
    lo_i = np.clip(np.searchsorted(ti, pts[:, 0]) - 1, 0, ti.size - 2)
    a = np.where(along_outer, to[lo_o], ti[lo_i])
    b = np.where(along_outer, to[lo_o + 1], ti[lo_i + 1])
    fixed = np.where(along_outer, ti[ni_near], to[no_near])
    # grid indices (row, column) of the edge's two ends, and their verdicts from the map itself
    r_a = np.where(along_outer, lo_o, no_near)
    c_a = np.where(along_outer, ni_near, lo_i)
    r_b = np.where(along_outer, lo_o + 1, no_near)
    c_b = np.where(along_outer, ni_near, lo_i + 1)
    s_a, s_b = stable[r_a, c_a], stable[r_b, c_b]
    ok = decided[r_a, c_a] & decided[r_b, c_b] & (s_a != s_b)
    step = np.abs(b - a)
    pos = np.where(along_outer, pts[:, 1], pts[:, 0])
    refined = np.zeros(pos.size, bool)
    todo = np.flatnonzero(ok)
    if iterations and todo.size:
        t0 = time.perf_counter()
        lo_t, hi_t = a[todo].copy(), b[todo].copy()
        sa = s_a[todo].copy()
        alive = np.ones(todo.size, bool)
        for k in range(iterations):
            mid = 0.5 * (lo_t + hi_t)
            ao = along_outer[todo]
            vo = np.where(ao, mid, fixed[todo])
            vi = np.where(ao, fixed[todo], mid)
            sel = np.flatnonzero(alive)
            if sel.size == 0:
                break
            vals = {names[0]: _v(vo[sel], outer.log), names[1]: _v(vi[sel], inner.log)}
            r = evaluator(vals)
            good = np.isin(r.status, _DECIDED)
            same = np.asarray(r.stable, bool) == sa[sel]
            upd = sel[good]
            lo_t[upd] = np.where(same[good], mid[upd], lo_t[upd])
            hi_t[upd] = np.where(same[good], hi_t[upd], mid[upd])
            alive[sel[~good]] = False  # a hole inside the bracket: keep the last bracket
            if budget is not None and time.perf_counter() - t0 > budget:
                break  # out of time: every vertex keeps its current (narrowed) bracket
        pos[todo] = 0.5 * (lo_t + hi_t)
        refined[todo] = np.abs(hi_t - lo_t) < np.abs(b[todo] - a[todo])
        width = np.abs(b - a)
        width[todo] = np.abs(hi_t - lo_t)
    else:
        width = np.abs(b - a)
    rel = np.divide(width, step, out=np.ones_like(width), where=step > 0)
    out_o = np.where(along_outer, pos, fixed)
    out_i = np.where(along_outer, fixed, pos)
    # reassemble the curves with NaN separators
    sizes = [len(ln) for ln in lines]
    bounds = np.cumsum([0, *sizes])
    co: list[Any] = []
    ci: list[Any] = []
    rf: list[Any] = []
    wd: list[Any] = []
    for s0, s1 in zip(bounds[:-1], bounds[1:]):
        co += [_v(out_o[s0:s1], outer.log), [np.nan]]
        ci += [_v(out_i[s0:s1], inner.log), [np.nan]]
        rf += [refined[s0:s1], [False]]
        wd += [rel[s0:s1], [np.nan]]
    return Boundary(names, (np.concatenate(co)[:-1], np.concatenate(ci)[:-1]),
                    np.concatenate(rf)[:-1].astype(bool), np.concatenate(wd)[:-1])
