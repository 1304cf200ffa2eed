r"""The one verdict dispatcher: which route decides which point.

:func:`decide` (parameter points) and :func:`decide_model` (one linear model)
build a :class:`~._base.Context` and hand it to :func:`_choose`, the only
function that chooses among the routes.  The rule is one ordered list,
:data:`ROUTES`, cheapest first:

1. ``closed-grid`` — the compiled Hurwitz kernel of a grid (closed form);
2. ``charpoly-grid`` — certified roots of the exact characteristic
   polynomial on a 2-D grid (any model size);
3. ``closed-interval`` — bounded closed-form entries, interval quartic,
   certified Routh–Hurwitz;
4. ``closed-exact`` — the closed form in exact rational arithmetic;
5. ``quartic-interval`` — interval quartic of numerically linearized 2x2
   matrices;
6. ``eigen-bounds`` — eigenvalues of the linearization with condition-number
   bounds (any size, pads kept as states);
7. ``pencil-refined`` — QZ eigenpairs of the pencil refined by Newton's
   method, with componentwise bounds (beside a massless pad's own huge mode);
8. ``extended`` — 40-digit eigenvalues with componentwise bounds (small
   systems).

Each route says whether it applies to the call (model, space, axes, input
kind) and which pending points it can take; it returns *certified* codes.  A
point is settled by the first route that certifies it — with ``max_real``
wanted, only if the route's ``max_real`` has the verdict's sign (stable ⇔
``max_real < 0``) — and the route is recorded in ``method``; every other
point goes on to the next route, and a point no route settles is
``UNDECIDED``.  Before the routes, the operating points are decided once
(:mod:`._linear`: validity, triviality of the silent motion, the silent
motions and contact), and after them the carrier of every verdict.

Adding a route is one module with a :class:`~._base.Route` subclass and one
:func:`register` call (``docs/architecture.md``).
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

import numpy as np

from ...status import PointStatus
from ._base import DECIDED, STABLE, UNDECIDED, UNSTABLE, Context, Points, Route, Verdicts
from ._linear import group_of_model, linear_groups, operating_points
from .charpoly_grid import CharpolyGrid
from .closed_exact import ClosedExact
from .closed_grid import ClosedGrid
from .closed_interval import ClosedInterval
from .eigen_bounds import EigenBounds, state_labels
from .extended import Extended
from .pencil_refined import PencilRefined
from .quartic_interval import QuarticInterval

if TYPE_CHECKING:
    from ...codegen.engine import Engine
    from ...model.parameters import ParameterSpace

__all__ = ["decide", "decide_model", "point_eigenvalues", "ROUTES", "register", "route_names", "MODES"]

#: The routes, in the order the dispatcher tries them.
ROUTES: list[Route] = [ClosedGrid(), CharpolyGrid(), ClosedInterval(), ClosedExact(), QuarticInterval(), EigenBounds(),
                       PencilRefined(), Extended()]
#: What a verdict judges: every eigenvalue, or the disk's modes (a massless pad's own tangential-rate mode left out).
MODES = ("all", "disk")


def register(route: Route, *, before: str | None = None) -> None:
    """Add a route to :data:`ROUTES` (at the end, or before the route named ``before``).

    Parameters
    ----------
    route : Route
        The route (its :attr:`~._base.Route.name` must be new).
    before : str, optional
        The name of the route it goes before.

    Raises
    ------
    ValueError
        A route of that name exists, or ``before`` names none.
    """
    if any(r.name == route.name for r in ROUTES):
        raise ValueError(f"a route named {route.name!r} is registered already")
    if before is None:
        ROUTES.append(route)
        return
    names = [r.name for r in ROUTES]
    if before not in names:
        raise ValueError(f"no route named {before!r}; routes: {', '.join(names)}")
    ROUTES.insert(names.index(before), route)


def route_names() -> tuple[str, ...]:
    """``("none", <route names in order>)``: the meanings of a result's ``route`` codes.

    Returns
    -------
    tuple of str
    """
    return ("none",) + tuple(r.name for r in ROUTES)


def _check_modes(modes: str) -> None:
    if modes not in MODES:
        from ...errors import ParameterError

        raise ParameterError(f"modes must be one of {', '.join(MODES)}; got {modes!r}", parameter="modes")


def decide(engine: Engine, space: ParameterSpace, points: Points, *, eigen: bool = True,
           modes: str = "all", carriers: str = "all") -> Verdicts:
    """Statuses and certified verdicts of parameter points, each decided by the first route that can.

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The parameter space of the points.
    points : Points
        The points (broadcast arrays or a grid).
    eigen : bool
        Also compute ``max_real`` and the frequency where a cheaper certified verdict exists.
    modes : {"all", "disk"}
        Judge every eigenvalue (default), or leave out the modes carried by a massless pad's own tangential
        rate (reported as carriers, not judged).
    carriers : {"all", "cheap"}
        Name the carrier of every verdict (default), or only where it costs nothing (the eigenvalue routes,
        disk-only models; maps and sweeps: a larger model's grid decided from its characteristic polynomial
        would otherwise pay one inverse iteration per point).

    Returns
    -------
    Verdicts
        Arrays of ``points.shape``.
    """
    _check_modes(modes)
    chunk = batch_points(engine)
    if points.size > chunk:  # large systems: bounded memory, the points decided in flat chunks
        return _decide_chunks(engine, space, points, chunk, eigen=eigen, modes=modes, carriers=carriers)
    ctx = _operating(engine, space, points, eigen=eigen, modes=modes, carriers_wanted=carriers)
    return _choose(ctx).reshape(points.shape)


def _operating(engine: Engine, space: ParameterSpace, points: Points, **kw: Any) -> Context:
    """The context of deciding ``points`` (``kw`` as :class:`~._base.Context`), whether the closed-form routes
    apply to them, and their operating points (:func:`~._linear.operating_points`)."""
    ctx = Context(engine, space, points, points.size, **kw)
    ctx.closed = bool(engine.closed_route(space, points.names)) if engine.caps.closed_form else False
    operating_points(ctx)
    return ctx


#: Memory the linear systems of one batch of points may take (a model's batch size follows from its size).
BATCH_BYTES = 256 << 20


def batch_points(engine: Engine) -> int:
    """How many points one batch of :func:`decide` holds: every point's ``M, D, K`` and its state matrices
    (about ``20 (2n)^2`` doubles with the eigenvectors) within :data:`BATCH_BYTES`; unbounded for small models."""
    m = 2 * engine.caps.n + engine.caps.m
    if m <= 32:
        return 1 << 62
    return max(1, BATCH_BYTES // (8 * 20 * m * m))


def _flat_chunks(space: ParameterSpace, points: Points, chunk: int) -> Iterator[tuple[int, Points]]:
    """``points`` in flat slices of ``chunk`` points, each with the flat index of its first point."""
    shape = points.shape
    flat = {k: np.broadcast_to(np.asarray(v, dtype=float), shape).reshape(-1) for k, v in points.arrays.items()}
    sett = {k: np.broadcast_to(np.asarray(v, dtype=float), shape).reshape(-1) for k, v in points.settable.items()}
    valid = np.broadcast_to(points.valid, shape).reshape(-1)
    for s0 in range(0, points.size, chunk):
        sl = slice(s0, s0 + chunk)
        yield s0, Points(space, {k: v[sl] for k, v in flat.items()}, points.names, valid=valid[sl],
                         settable={k: v[sl] for k, v in sett.items()})


def _decide_chunks(engine: Engine, space: ParameterSpace, points: Points, chunk: int, **kw: Any) -> Verdicts:
    """:func:`decide` on flat slices of ``points`` (no grid route applies to such large systems)."""
    shape = points.shape
    parts = [decide(engine, space, sub, **kw) for _, sub in _flat_chunks(space, points, chunk)]

    def cat(f: str) -> np.ndarray:
        return np.concatenate([getattr(p, f) for p in parts]).reshape(shape)

    return Verdicts(cat("status"), cat("code"), cat("max_real"), cat("frequency"), cat("bound"), cat("carrier"),
                    cat("method"), parts[0].carriers, parts[0].methods)


def point_eigenvalues(engine: Engine, space: ParameterSpace, points: Points) -> np.ndarray:
    """Every eigenvalue of the linear system at each point, batched (floating point; no verdict).

    The linear systems are those :func:`decide` builds (:func:`~._linear.linear_groups`: batched zero-state
    Jacobians of trivial silent motions, the compiled Jacobian at non-trivial ones, a matrix model's
    matrices), their state matrices' eigenvalues computed one batch at a time.  Used for per-mode outputs
    (``brakesqueal uq --modes``).

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The parameter space of the points.
    points : Points
        The points.

    Returns
    -------
    ndarray of complex, shape (points.size, m)
        Per flat point the eigenvalues of its state matrix (``m`` the largest state size, smaller systems padded
        with NaN); a row of NaN where the point has no silent motion, invalid parameters or an unusable system.
    """
    size = points.size
    chunk = batch_points(engine)
    parts: list[tuple[np.ndarray, np.ndarray]] = []
    subs = _flat_chunks(space, points, chunk) if size > chunk else iter([(0, points)])
    for s0, sub in subs:
        ctx = _operating(engine, space, sub, eigen=True, modes="all")
        idx = np.flatnonzero(np.isin(ctx.status, DECIDED))
        for g in linear_groups(ctx, idx) if idx.size else []:
            S, good = g.states_matrices()
            if good.any():
                with np.errstate(all="ignore"):
                    parts.append((s0 + g.idx[good], np.linalg.eigvals(S[good])))
    width = max((lam.shape[1] for _, lam in parts), default=0)
    out = np.full((size, width), np.nan + 0j)
    for i, lam in parts:
        out[i, :lam.shape[1]] = lam
    out[np.any(np.isinf(out), axis=1)] = np.nan  # an infinite eigenvalue: an unusable system
    return out


def decide_model(lm: Any, *, eigen: bool = True, modes: str = "all") -> Verdicts:
    """The certified verdict of one linear model (:class:`~..linear.LinearModel`).

    A model from :func:`~..linear.linearize` (it carries its engine and parameters) is decided as the
    parameter point it is, so that its verdict is the one maps, sweeps and crossings give there; a model built
    by hand is decided from its matrices alone.

    Parameters
    ----------
    lm : LinearModel
        The linear model.
    eigen : bool
        Also compute ``max_real`` and the frequency where a cheaper certified verdict exists.
    modes : {"all", "disk"}
        As :func:`decide`.

    Returns
    -------
    Verdicts
        Of shape ``()``.
    """
    _check_modes(modes)
    engine = getattr(lm, "engine", None)
    points = space = None
    if engine is not None:
        from ...model.parameters import ParameterSpace

        space = ParameterSpace.from_parameters(lm.params)
        points = Points(space, space.arrays({}))
    ctx = Context(engine, space, points, 1, eigen=eigen, modes=modes)
    trivial = bool(getattr(getattr(lm, "silent", None), "trivial", False))
    ctx.status[0] = int(PointStatus.OK if trivial or engine is None else PointStatus.OK_NONTRIVIAL)
    ctx.trivial[0] = trivial and engine is not None
    ctx.models[0] = lm
    ctx.add_group(group_of_model(lm, np.array([0])))
    return _choose(ctx)


def _consistent(code: np.ndarray, mr: np.ndarray, eigen: bool) -> np.ndarray:
    """Codes a route certified and, with ``max_real`` wanted, whose ``max_real`` has the verdict's sign."""
    ok = (code == STABLE) | (code == UNSTABLE)
    if eigen:
        with np.errstate(invalid="ignore"):
            ok &= ((code == STABLE) & (mr < 0)) | ((code == UNSTABLE) & (mr >= 0))
    return ok


def _choose(ctx: Context) -> Verdicts:
    """The one place that chooses routes: each pending point goes through :data:`ROUTES` until one settles it."""
    pending = np.flatnonzero(np.isin(ctx.status, DECIDED))
    methods = route_names()
    for k, route in enumerate(ROUTES, start=1):
        if pending.size == 0:
            break
        if not route.applies(ctx):
            continue
        idx = route.take(ctx, pending)
        if idx.size == 0:
            continue
        res = route.run(ctx, idx)
        alive = np.isin(ctx.status[idx], DECIDED)  # a per-point linearization may have found no silent motion
        ok = _consistent(res.code, res.max_real, ctx.eigen) & alive
        done = idx[ok]
        ctx.code[done] = res.code[ok]
        ctx.max_real[done] = res.max_real[ok]
        ctx.frequency[done] = res.frequency[ok]
        ctx.bound[done] = res.bound[ok]
        ctx.carrier[done] = res.carrier[ok]
        ctx.method[done] = k
        # what an undecided point's routes computed is kept for information (the first value found)
        info = idx[~ok & alive]
        fill = np.isnan(ctx.max_real[info])
        ctx.max_real[info[fill]] = res.max_real[~ok & alive][fill]
        ctx.frequency[info[fill]] = res.frequency[~ok & alive][fill]
        pending = np.setdiff1d(pending, done, assume_unique=True)
        pending = pending[np.isin(ctx.status[pending], DECIDED)]
    ctx.status[pending] = int(PointStatus.UNDECIDED)
    ctx.code[pending] = UNDECIDED
    _carriers(ctx)
    return Verdicts(ctx.status, ctx.code, ctx.max_real, ctx.frequency, ctx.bound, ctx.carrier.astype(np.int16),
                    ctx.method, ctx.carriers, methods)


def _carriers(ctx: Context) -> None:
    """The carrier of every verdict a route left without one: the component with the largest participation in
    the least-stable eigenvalue's mode (:func:`~..robust.state_analysis`'s rule), by one step of inverse
    iteration from the eigenvalue the route found (right and left vectors), or from the eigenvalues."""
    todo = np.flatnonzero(np.isin(ctx.status, DECIDED) & (ctx.carrier < 0))
    if todo.size == 0:
        return
    if ctx.disk_only:
        ctx.carrier[todo] = 0
        return
    if ctx.carriers_wanted != "all":
        return
    for g in linear_groups(ctx, todo):
        S, good = g.states_matrices()
        sel = np.flatnonzero(good)
        if sel.size == 0:
            continue
        labels = state_labels(ctx, g)
        idx = g.idx[sel]
        lam = ctx.max_real[idx] + 2j * np.pi * ctx.frequency[idx]
        ctx.carrier[idx] = _participation_carrier(S[sel], lam, labels)


def _participation_carrier(S: np.ndarray, lam: np.ndarray, labels: np.ndarray) -> np.ndarray:
    """Per system, the label with the largest participation ``|x_k| |y_k|`` in the mode of ``lam`` (right and
    left eigenvectors by one step of inverse iteration; the eigenvalue with the largest real part where ``lam``
    is not finite)."""
    N, m = S.shape[0], S.shape[-1]
    lam = np.array(lam, dtype=complex)
    missing = ~np.isfinite(lam)
    if missing.any():
        w = np.linalg.eigvals(S[missing])
        lam[missing] = w[np.arange(w.shape[0]), np.argmax(w.real, axis=1)]
    shift = lam * (1 + 1e-10) + 1e-300
    B = S - shift[:, None, None] * np.eye(m)
    b = np.ones((N, m, 1), dtype=complex)
    with np.errstate(all="ignore"):
        try:
            x = np.linalg.solve(B, b)[..., 0]
            y = np.linalg.solve(np.conj(np.swapaxes(B, 1, 2)), b)[..., 0]
        except np.linalg.LinAlgError:
            x = y = np.full((N, m), np.nan + 0j)
        part = np.nan_to_num(np.abs(x) * np.abs(y))
    nl = int(labels.max()) + 1 if labels.size else 1
    per = np.zeros((N, nl))
    for j in range(nl):
        per[:, j] = part[:, labels == j].sum(axis=1)
    out = np.argmax(per, axis=1).astype(np.int64)
    out[~np.any(per > 0, axis=1)] = -1
    return out
