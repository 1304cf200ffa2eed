"""Certified stable windows of one design variable (e.g. ``k_ip`` at ``mu = 0.5``: the paper's points B and A)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Annotated

import numpy as np

from ..errors import ParameterError
from ..validation import Range, validated
from ._objectives import REL_WIDTH

if TYPE_CHECKING:
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace

__all__ = ["stable_windows"]


def _log_scale(lo: float, hi: float) -> bool:
    return lo > 0 and hi / lo >= 100


@validated
def stable_windows(engine: Engine, space: ParameterSpace, name: str, within: Sequence[float], *,
                   box: Mapping[str, Sequence[float]] | None = None,
                   grid: Annotated[int, Range(2, 100_000)] = 64,
                   steps: Annotated[int, Range(1, 60)] = 40,
                   max_boxes: Annotated[int, Range(1, 10_000_000)] = 400) -> list[tuple[float, float]]:
    """Certified-stable intervals of one variable within a range, the other parameters at the space's values
    (or over a whole box of them).

    Stable runs are located on a grid of ``within`` (logarithmic when ``lo > 0`` and ``hi/lo >= 100``); each run
    is then widened by bisection to the end of its certified-stable interval: without ``box`` by
    :func:`brakesqueal.robust.stable_margins` (the window of ``name`` around the run's middle), with ``box`` by
    :func:`brakesqueal.robust.robust_box` on ``[x0, x] x box``.  Every returned interval is certified stable (a
    lower bound of the true window, to ``range / 2**steps`` on the grid's scale); a window narrower than the grid's
    step may be missed.

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The parameter space (a model with a closed-form quartic; ties apply).
    name : str
        A settable name.
    within : sequence of float
        ``(lo, hi)``, ``lo < hi``: where to look.
    box : Mapping[str, sequence of float], optional
        Other settable names -> ``(lo, hi)``: certify each window for every point of this box.
    grid : int
        Grid points of ``within``.
    steps : int
        Bisection steps per end.
    max_boxes : int
        Branch-and-bound budget per decision.

    Returns
    -------
    list of (float, float)
        The windows, in increasing order (empty: no certified-stable point on the grid).

    Raises
    ------
    ParameterError
        ``name`` not settable, an empty, reversed or non-finite ``within``, ``name`` also in ``box``, a model
        without a closed-form quartic or a silent motion that is not trivial (certified decisions need both).
    """
    from ..analysis.crossings import merge_ranges
    from ..robust import decide_boxes, stable_margins

    space.check_axis(name)
    if len(within) != 2:
        raise ParameterError(f"stable_windows: within must be (lo, hi) of '{name}'; got {list(within)!r}",
                             parameter=name)
    lo, hi = float(within[0]), float(within[1])
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise ParameterError(f"stable_windows: the range of '{name}' must be finite with lo < hi; got [{lo!r}, "
                             f"{hi!r}]", parameter=name)
    bx = {k: (float(v[0]), float(v[1])) for k, v in (box or {}).items()}
    if name in bx:
        raise ParameterError(f"stable_windows: '{name}' is the window's variable; it cannot also be in the box",
                             parameter=name)
    log = _log_scale(lo, hi)
    g = np.geomspace(lo, hi, grid) if log else np.linspace(lo, hi, grid)
    if not bx:
        from ..analysis.points import evaluate

        ok = np.asarray(evaluate(engine, space, {name: g}).stable, dtype=bool)
    else:
        names = (name, *bx)
        w = np.maximum(np.abs(g) * REL_WIDTH, REL_WIDTH)
        L = np.column_stack([g - w, *[np.full(grid, a) for a, _ in bx.values()]])
        H = np.column_stack([g + w, *[np.full(grid, b) for _, b in bx.values()]])
        L[:, 0] = np.maximum(L[:, 0], lo)
        H[:, 0] = np.minimum(H[:, 0], hi)
        ok = np.asarray(decide_boxes(engine, space, names, L, H, max_boxes=max_boxes).code) == 1
    runs: list[tuple[int, int]] = []
    i = 0
    while i < grid:
        if ok[i]:
            j = i
            while j + 1 < grid and ok[j + 1]:
                j += 1
            runs.append((i, j))
            i = j + 1
        else:
            i += 1
    out: list[tuple[float, float]] = []
    for a, b in runs:
        m = (a + b) // 2
        x0 = float(g[m])
        if out and out[-1][0] <= x0 <= out[-1][1]:
            continue  # the previous run's window already reaches here
        if not bx and lo > 0:
            try:
                mg = stable_margins(engine, space.with_values({name: x0}), [name], within={name: (lo, hi)},
                                    steps=steps, max_boxes=max_boxes)
            except ParameterError:  # the grid's verdict is not certified by a box decision: bisect below
                pass
            else:
                out.append(mg.windows[name])
                continue
        win = _bisect_window(engine, space, name, x0, lo, hi, bx, steps, max_boxes, log)
        if win is not None:
            out.append(win)
    return merge_ranges(out)


def _bisect_window(engine: Engine, space: ParameterSpace, name: str, x0: float, lo: float, hi: float,
                   bx: Mapping[str, tuple[float, float]], steps: int, max_boxes: int, log: bool
                   ) -> tuple[float, float] | None:
    """The certified window of ``name`` about ``x0`` over ``bx``: bisection of ``[x, x0]`` and ``[x0, x]`` (None:
    ``x0`` itself is not certified stable)."""
    from ..robust import robust_box

    w0 = max(abs(x0) * REL_WIDTH, REL_WIDTH)
    # the first decision is not guarded: a model without a closed form, a non-trivial silent motion, ... is refused
    # here in one line instead of passing off a single point as a window
    if robust_box(engine, space, {name: (x0 - w0, x0 + w0), **bx}, max_boxes=max_boxes).verdict != "stable":
        return None

    def stable(a: float, b: float) -> bool:
        if b <= a:
            w = max(abs(a) * REL_WIDTH, REL_WIDTH)
            a, b = a - w, b + w
        try:
            r = robust_box(engine, space, {name: (a, b), **bx}, max_boxes=max_boxes)
        except ParameterError:  # the box reaches invalid parameters
            return False
        return bool(r.verdict == "stable")

    def toward(end: float, t: float) -> float:
        if t >= 1:
            return end
        return x0 * (end / x0) ** t if log else x0 + t * (end - x0)

    def reach(end: float, below: bool) -> float:
        test = (lambda t: stable(toward(end, t), x0)) if below else (lambda t: stable(x0, toward(end, t)))
        if test(1.0):
            return end
        a, b = 0.0, 1.0
        for _ in range(steps):
            c = 0.5 * (a + b)
            a, b = (c, b) if test(c) else (a, c)
        return toward(end, a)

    return reach(lo, True), reach(hi, False)
