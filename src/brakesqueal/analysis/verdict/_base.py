r"""What the verdict dispatcher works on: points, their operating points and linear systems, routes, results.

A *route* (one module of this package) decides stability certifiably for a
batch of points it can take; the dispatcher (:mod:`._dispatch`) owns the
choice of routes.  This module holds what they share:

* :class:`Points` — parameter points of one parameter space (broadcast
  arrays, possibly a grid), with their validity;
* :class:`Context` — one :func:`~._dispatch.decide` call: the request, the
  results so far, and, computed once on demand, the operating points (which
  silent motion is trivial, the silent motions of the others) and the linear
  systems at them (:class:`LinearGroup`);
* :class:`Route` — the protocol of a route;
* :class:`Verdicts` — the result: per point a status, a certified verdict
  code, ``max_real``, frequency, error bound, carrier mode and route.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from ...status import PointStatus
from ..robust import STABLE, UNDECIDED, UNSTABLE

if TYPE_CHECKING:
    from ...codegen.engine import Engine
    from ...model.parameters import ParameterSpace

__all__ = ["STABLE", "UNSTABLE", "UNDECIDED", "Points", "Grid", "LinearGroup", "Context", "Route", "Result",
           "Verdicts", "carrier_labels", "DECIDED"]

#: Statuses of points with a verdict.
DECIDED = (int(PointStatus.OK), int(PointStatus.OK_NONTRIVIAL))


@dataclass(frozen=True)
class Grid:
    """A full grid over settable names, in dimension order (the last axis the contiguous one).

    Attributes
    ----------
    names : tuple of str
        The axes.
    values : tuple of ndarray
        The values of each axis (1-D).
    """

    names: tuple[str, ...]
    values: tuple[np.ndarray, ...]

    @property
    def shape(self) -> tuple[int, ...]:
        """Points per axis."""
        return tuple(int(v.size) for v in self.values)


class Points:
    """Parameter points of one parameter space: every model parameter as arrays broadcastable to one shape.

    Parameters
    ----------
    space : ParameterSpace
        The parameter space (any model).
    arrays : Mapping[str, ndarray]
        Every model parameter (:meth:`ParameterSpace.arrays
        <brakesqueal.model.parameters.ParameterSpace.arrays>`).
    names : tuple of str
        The settable names that vary across the points (the axes of a map, a path's parameter); the
        closed-form route applies when the silent motion is identically trivial along them.
    valid : ndarray of bool, optional
        Validity (default :func:`valid_points`).
    grid : Grid, optional
        The points are this full grid (``arrays`` broadcast from its axes, in its dimension order): the
        grid routes may take them.
    settable : Mapping[str, ndarray], optional
        The values of the varying settable names (broadcastable to the points' shape), where they are at hand.
    """

    def __init__(self, space: ParameterSpace, arrays: Mapping[str, Any], names: tuple[str, ...] = (), *,
                 valid: np.ndarray | None = None, grid: Grid | None = None,
                 settable: Mapping[str, Any] | None = None) -> None:
        self.space = space
        self.arrays = dict(arrays)
        self.names = tuple(names)
        self.grid = grid
        self.settable = dict(settable or {})
        shape = tuple(np.broadcast_shapes(*(np.shape(v) for v in self.arrays.values())))
        self.shape: tuple[int, ...] = shape or (1,)  # one point: a length-1 batch
        ok = valid_points(space, self.arrays) if valid is None else valid
        self.valid = np.broadcast_to(np.asarray(ok, dtype=bool), self.shape)
        self._vecs: list[np.ndarray] | None = None

    @classmethod
    def of(cls, space: ParameterSpace, values: Mapping[str, Any], *, grid: bool = False) -> Points:
        """Points at settable names → values (broadcastable arrays), or the grid over them (``grid=True``:
        ``values`` are the 1-D axes, in dimension order)."""
        names = tuple(values)
        if grid:
            axes = [np.asarray(values[n], dtype=float).ravel() for n in names]
            nd = len(axes)
            shaped = {n: a.reshape([-1 if i == k else 1 for i in range(nd)]) for k, (n, a) in enumerate(zip(names,
                                                                                                              axes))}
            arr = space.arrays(shaped)
            return cls(space, arr, names, grid=Grid(names, tuple(axes)), settable=shaped)
        vals = {k: np.asarray(v, dtype=float) for k, v in values.items()}
        return cls(space, space.arrays(vals), names, settable=vals)

    @property
    def size(self) -> int:
        """Number of points."""
        return math.prod(self.shape)

    def rows(self, flat: np.ndarray) -> np.ndarray:
        """Packed parameter vectors (model packing order, compliances) of the points ``flat`` (flat indices)."""
        if self._vecs is None:
            self._vecs = [np.asarray(v, dtype=float) for v in self.space.vectors({k: compact(v)
                                                                                  for k, v in self.arrays.items()})]
        flat = np.asarray(flat, dtype=np.int64)
        if not self._vecs:
            return np.zeros((flat.size, 0))
        ix = np.unravel_index(flat, self.shape)
        return np.ascontiguousarray(np.stack([np.broadcast_to(v, self.shape)[ix] for v in self._vecs], axis=1))

    def settable_values(self, name: str) -> np.ndarray:
        """The values of a varying settable name at every point (the points' shape).

        Parameters
        ----------
        name : str
            One of :attr:`names`.

        Returns
        -------
        ndarray
        """
        if name not in self.settable:
            raise KeyError(f"the points do not carry the values of {name!r}")
        return np.broadcast_to(np.asarray(self.settable[name], dtype=float), self.shape)

    def values(self, flat: int) -> dict[str, float]:
        """Every model parameter's value at point ``flat``."""
        pi = np.unravel_index(int(flat), self.shape)
        return {n: float(np.broadcast_to(self.arrays[n], self.shape)[pi]) for n in self.space.model.parameters}


def compact(a: Any) -> np.ndarray:
    """The smallest broadcastable array equal to a broadcast view (stride-0 axes reduced to length 1).

    Parameters
    ----------
    a : array_like
        Typically a view returned by :func:`numpy.broadcast_to`.

    Returns
    -------
    ndarray
        Same values, broadcastable to ``a.shape``.
    """
    a = np.asarray(a)
    return a[tuple(slice(0, 1) if st == 0 and n > 1 else slice(None) for st, n in zip(a.strides, a.shape))]


def valid_points(space: ParameterSpace, arr: Mapping[str, Any]) -> np.ndarray:
    """Validity of broadcast parameter arrays, evaluated on their compact forms (cheap for grids).

    The same conditions as :meth:`ParameterSpace.valid
    <brakesqueal.model.parameters.ParameterSpace.valid>` (every role's
    interval, the disk thickness, pads on the disk, caliper stiffnesses, from
    :func:`brakesqueal.model.roles.parameter_roles`), but combined per array
    shape first, so that a grid whose parameters each depend on one axis costs
    only a few full-size operations.

    Parameters
    ----------
    space : ParameterSpace
        The parameter space.
    arr : Mapping[str, ndarray]
        Model parameter arrays (:meth:`ParameterSpace.arrays`).

    Returns
    -------
    ndarray of bool
        Broadcastable to the arrays' shape.
    """
    roles = space.model.roles()
    parts: dict[tuple[int, ...], np.ndarray] = {}

    def add(c: Any) -> None:
        c = np.asarray(c)
        parts[c.shape] = parts[c.shape] & c if c.shape in parts else c

    def value(v: Any) -> np.ndarray:
        return compact(np.asarray(arr[v], dtype=float)) if isinstance(v, str) else np.asarray(float(v))

    with np.errstate(invalid="ignore"):
        for name, uses in roles.uses.items():
            v = value(name)
            for role, _ in uses:
                add(role.contains(v))
        hu, hl = roles.thickness
        add(value(hu) + value(hl) > 0)
        Rv = value(roles.disk_radius)
        for _, r in roles.pad_radii:
            add(value(r) <= Rv)
        for _, _, k in roles.caliper_dofs:
            add(value(k) > 0)
    ok: Any = np.True_
    for shape in sorted(parts, key=lambda sh: (math.prod(sh), sh)):
        ok = ok & parts[shape]
    return np.asarray(ok)


def carrier_labels(engine: Engine) -> tuple[tuple[str, ...], np.ndarray, np.ndarray]:
    """The carrier labels of a model and the label of each coordinate and each pad deformation.

    A mode is *carried* by the component whose states hold the largest share of its (balanced) eigenvector:
    the disk (its tilts ``q1``, ``q2``), a pad (its own coordinates), a caliper, or — for a massless pad whose
    deformation keeps a rate state — that pad's tangential rate (a non-oscillatory mode of the pad alone).

    Parameters
    ----------
    engine : Engine
        The model's engine.

    Returns
    -------
    labels : tuple of str
        ``"disk"``, ``"pad <name>"``, ``"caliper <name>"``, ``"pad <name> tangential rate"``.
    coord_label : ndarray of int, shape (n,)
        Index into ``labels`` of each coordinate.
    pad_label : ndarray of int, shape (m,)
        Index into ``labels`` of each pad deformation's rate state.
    """
    if engine.caps.kind == "matrices":  # one structure: no component owns a coordinate
        return ("structure",), np.zeros(engine.caps.n, dtype=np.int64), np.zeros(0, dtype=np.int64)
    spec = engine.spec
    labels: list[str] = ["disk"]
    owner: dict[str, int] = {"q1": 0, "q2": 0}
    for pad in spec.pads:
        for c in pad.coordinates():
            if f"pad {pad.name}" not in labels:
                labels.append(f"pad {pad.name}")
            owner[c] = labels.index(f"pad {pad.name}")
    for cal in spec.calipers:
        for c in cal.coordinates():
            if f"caliper {cal.name}" not in labels:
                labels.append(f"caliper {cal.name}")
            owner[c] = labels.index(f"caliper {cal.name}")
    rate: dict[str, int] = {}
    for pad in spec.pads:
        for d in pad.deformations():
            labels.append(f"pad {pad.name} tangential rate")
            rate[d] = len(labels) - 1
    coord = np.array([owner.get(c, 0) for c in engine.caps.coords], dtype=np.int64)
    pads = np.array([rate.get(a, 0) for a in engine.caps.algebraic], dtype=np.int64)
    return tuple(labels), coord, pads


@dataclass
class LinearGroup:
    """Linear systems at a set of points, all of one shape.

    Either second order (``M q'' + D q' + K q = 0``, ``k == 0``; ``E``, ``A`` are then ``None`` until asked
    for) or a descriptor system ``E xi' = A xi`` in ``xi = (delta Q, delta Qdot, delta L_kept)`` with ``k``
    pad states kept (``states`` their indices among the model's pad deformations).

    Attributes
    ----------
    idx : ndarray of int
        Flat indices of the points.
    n, k : int
        Coordinates and kept pad states.
    M, D, K : ndarray or None
        ``(G, n, n)`` for second-order groups.
    E, A : ndarray or None
        ``(G, 2n + k, 2n + k)`` for descriptor groups.
    states : ndarray of int
        The kept pad deformations.
    """

    idx: np.ndarray
    n: int
    k: int
    M: np.ndarray | None = None
    D: np.ndarray | None = None
    K: np.ndarray | None = None
    E: np.ndarray | None = None
    A: np.ndarray | None = None
    states: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    def descriptor(self) -> tuple[np.ndarray, np.ndarray]:
        """``(E, A)`` of every system (second-order groups in the state ``(delta Q, delta Qdot)``)."""
        if self.E is not None and self.A is not None:
            return self.E, self.A
        assert self.M is not None and self.D is not None and self.K is not None
        G, n = self.M.shape[0], self.n
        I, Z = np.broadcast_to(np.eye(n), (G, n, n)), np.zeros((G, n, n))
        E = np.concatenate([np.concatenate([I, Z], 2), np.concatenate([Z, self.M], 2)], 1)
        A = np.concatenate([np.concatenate([Z, I], 2), np.concatenate([-self.K, -self.D], 2)], 1)
        return E, A

    def states_matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """First-order state matrices of the systems (``E^-1 A`` of descriptor groups) and which are usable."""
        from ..robust import descriptor_states, state_matrices

        if self.E is None:
            assert self.M is not None and self.D is not None and self.K is not None
            return state_matrices(self.M, self.D, self.K)
        assert self.A is not None
        return descriptor_states(self.E, self.A)

    def subset(self, sel: np.ndarray) -> LinearGroup:
        """The group's systems at positions ``sel`` (a boolean mask or indices into :attr:`idx`)."""
        def take(X: np.ndarray | None) -> np.ndarray | None:
            return None if X is None else X[sel]

        return LinearGroup(self.idx[sel], self.n, self.k, take(self.M), take(self.D), take(self.K), take(self.E),
                           take(self.A), self.states)


@dataclass
class Result:
    """What a route returns for the points it was given (arrays of their length).

    Attributes
    ----------
    code : ndarray of uint8
        :data:`STABLE`, :data:`UNSTABLE` or :data:`UNDECIDED`.
    max_real, frequency : ndarray
        The least-stable eigenvalue's real part [1/s] and frequency [Hz] (NaN where not computed).
    bound : ndarray
        An error bound of ``max_real`` where the route certified the verdict through it (NaN otherwise: e.g.
        a Routh test; the default).
    carrier : ndarray of int
        The label index of the mode carrying the verdict (-1: not determined by the route; the default).
    """

    code: np.ndarray
    max_real: np.ndarray
    frequency: np.ndarray
    bound: np.ndarray = field(default_factory=lambda: np.zeros(0))
    carrier: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    def __post_init__(self) -> None:
        n = self.code.size
        if self.bound.size != n:
            self.bound = np.full(n, np.nan)
        if self.carrier.size != n:
            self.carrier = np.full(n, -1, dtype=np.int64)

    @classmethod
    def empty(cls, size: int) -> Result:
        """All undecided, nothing computed."""
        return cls(np.full(size, UNDECIDED, dtype=np.uint8), np.full(size, np.nan), np.full(size, np.nan))


class Route:
    """A stability route: one module, one certified way of deciding a batch of points.

    Subclasses set :attr:`name` (short, recorded in results) and :attr:`description`, and implement
    :meth:`applies` (may it take any point of this call: model, space, axes, input kind), :meth:`take`
    (which of the pending points it can take) and :meth:`run` (certified codes for them: a code it cannot
    certify is :data:`UNDECIDED`, never a guess).  :func:`~._dispatch.decide` calls them in the order of
    :data:`~._dispatch.ROUTES`.
    """

    name: ClassVar[str] = ""
    description: ClassVar[str] = ""

    def applies(self, ctx: Context) -> bool:
        """Whether the route may take any point of this call."""
        raise NotImplementedError

    def take(self, ctx: Context, pending: np.ndarray) -> np.ndarray:
        """The pending points (flat indices) the route can take."""
        return pending

    def run(self, ctx: Context, idx: np.ndarray) -> Result:
        """Certified verdicts at the points ``idx``."""
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"<route {self.name}>"


class ClosedFormRoute(Route):
    """A route of the closed form (2-DOF models): it takes the points with a trivial silent motion."""

    def applies(self, ctx: Context) -> bool:
        return ctx.points is not None and ctx.engine is not None and ctx.engine.caps.closed_form

    def take(self, ctx: Context, pending: np.ndarray) -> np.ndarray:
        return pending[ctx.trivial[pending]]


@dataclass
class Verdicts:
    """Statuses and certified verdicts of points (arrays of the points' shape).

    Attributes
    ----------
    status : ndarray of int8
        :class:`~brakesqueal.status.PointStatus` codes.
    code : ndarray of uint8
        :data:`STABLE`, :data:`UNSTABLE` or :data:`UNDECIDED` (undecided wherever the status has no verdict).
    max_real, frequency : ndarray of float
        The least-stable eigenvalue's real part [1/s] and ``|Im λ|/2π`` [Hz] (NaN where not computed); for
        decided points ``stable`` ⇔ ``max_real < 0`` (when computed).
    bound : ndarray of float
        Error bound of ``max_real`` where the route certified the verdict through it (smaller than
        ``|max_real|`` there), NaN where the verdict was certified otherwise (a Routh–Hurwitz test).
    carrier : ndarray of int16
        Index into :attr:`carriers` of the mode carrying the verdict (-1: none).
    method : ndarray of uint8
        Index into :attr:`methods` of the route that decided (0: none).
    carriers : tuple of str
        Carrier labels (:func:`carrier_labels`).
    methods : tuple of str
        ``("none", <route names>...)``.
    """

    status: np.ndarray
    code: np.ndarray
    max_real: np.ndarray
    frequency: np.ndarray
    bound: np.ndarray
    carrier: np.ndarray
    method: np.ndarray
    carriers: tuple[str, ...]
    methods: tuple[str, ...]

    @property
    def decided(self) -> np.ndarray:
        """Points with a verdict (status ``OK`` or ``OK_NONTRIVIAL``)."""
        return np.isin(self.status, DECIDED)

    @property
    def stable(self) -> np.ndarray:
        """Certified stable (never true without a verdict)."""
        return self.decided & (self.code == STABLE)

    def reshape(self, shape: tuple[int, ...]) -> Verdicts:
        """The same verdicts in another shape."""
        return Verdicts(self.status.reshape(shape), self.code.reshape(shape), self.max_real.reshape(shape),
                        self.frequency.reshape(shape), self.bound.reshape(shape), self.carrier.reshape(shape),
                        self.method.reshape(shape), self.carriers, self.methods)

    def carrier_name(self, i: int | tuple[int, ...] = 0) -> str | None:
        """The carrier label at a point (``None`` where there is none)."""
        c = int(np.asarray(self.carrier)[i])
        return self.carriers[c] if c >= 0 else None

    def method_name(self, i: int | tuple[int, ...] = 0) -> str:
        """The deciding route at a point (``"none"`` where none decided)."""
        return self.methods[int(np.asarray(self.method)[i])]


class Context:
    """One :func:`~._dispatch.decide` call: the request and everything computed for it once.

    (Linear systems are kept by :meth:`add_group`; :func:`~._linear.linear_groups` reads them.)

    Attributes
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace or None
        The parameter space (``None`` for linear systems given directly).
    points : Points or None
        The parameter points.
    size : int
        Number of points.
    eigen : bool
        ``max_real`` and ``frequency`` are wanted wherever a cheaper verdict exists.
    modes : str
        ``"all"``: every eigenvalue counts; ``"disk"``: the modes carried by a massless pad's own tangential rate
        are left out of the verdict (they are reported, not judged).
    carriers_wanted : str
        ``"all"``: every verdict gets its carrier; ``"cheap"``: only where a route gives it at no cost (the
        eigenvalue routes, every mode of a disk-only model) — grids of larger models decided from their
        characteristic polynomial leave it undetermined (-1).
    """

    def __init__(self, engine: Engine | None, space: ParameterSpace | None, points: Points | None, size: int, *,
                 eigen: bool, modes: str, carriers_wanted: str = "all") -> None:
        self.engine = engine
        self.carriers_wanted = carriers_wanted
        self.space = space
        self.points = points
        self.eigen = eigen
        self.modes = modes
        self.size = size
        self.status = np.full(size, int(PointStatus.INVALID), dtype=np.int8)
        self.code = np.full(size, UNDECIDED, dtype=np.uint8)
        self.max_real = np.full(size, np.nan)
        self.frequency = np.full(size, np.nan)
        self.bound = np.full(size, np.nan)
        self.carrier = np.full(size, -1, dtype=np.int16)
        self.method = np.zeros(size, dtype=np.uint8)
        #: points whose silent motion is the trivial one (decided once, :func:`~..equilibrium.trivial_rows`)
        self.trivial = np.zeros(size, dtype=bool)
        #: the closed-form route applies to every valid point (identically trivial along the varying names)
        self.closed = False
        #: silent motions (Q0, L0) of non-trivial points, NaN elsewhere
        self.z: np.ndarray | None = None
        #: linear systems already built: the groups, and per point its group (-1: none yet) and position in it
        self.groups: list[LinearGroup] = []
        self.group_of = np.full(size, -1, dtype=np.int64)
        self.pos_of = np.zeros(size, dtype=np.int64)
        #: per point, the LinearModel given or built per point (for the parameter routes' reports)
        self.models: dict[int, Any] = {}
        #: what routes compute once per call (kernels, tables)
        self.extra: dict[str, Any] = {}
        labels: tuple[str, ...] = ("disk",)
        coord = np.zeros(0, dtype=np.int64)
        pad = np.zeros(0, dtype=np.int64)
        if engine is not None:
            labels, coord, pad = carrier_labels(engine)
        self.carriers, self.coord_label, self.pad_label = labels, coord, pad

    def add_group(self, g: LinearGroup) -> None:
        """Keep the linear systems of a group (each point's system is built once per call)."""
        self.groups.append(g)
        self.group_of[g.idx] = len(self.groups) - 1
        self.pos_of[g.idx] = np.arange(g.idx.size)

    @property
    def disk_only(self) -> bool:
        """Every coordinate is the disk's and no pad keeps a state: every mode is a disk mode."""
        return bool(np.all(self.coord_label == 0)) and (self.engine is None or not self.engine.caps.dynamic_pads)
