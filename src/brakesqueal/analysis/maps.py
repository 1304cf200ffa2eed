"""Stability maps over two settable parameters of any model (chunked, bounded memory).

Every block of the grid is decided by the one verdict dispatcher
(:func:`~.verdict.decide`, the grid's points as a :class:`~.verdict.Grid`),
so the grid routes apply where they can (the compiled Hurwitz kernel of a
closed form, the exact characteristic polynomial of larger models) and every
point they leave goes on to the per-point routes; the map's ``method`` lists
the routes in the order they are tried, its ``route`` variable says which
decided each point, and its ``carrier`` variable which mode carries each
verdict.

Points where the silent motion does not exist, a pad loses contact or does not
slide, the parameters are invalid or the verdict cannot be decided are flagged
in ``status`` (:class:`~brakesqueal.status.PointStatus`) and never marked
stable.  No verdict depends on where an axis starts or on its sign.  Memory is
bounded: the points are computed in blocks of rows (``chunk_points`` bounds the
temporary memory per block); :func:`write_map` (the ``map`` command) writes
each block to its place in the NetCDF file at once and holds nothing else of
the map but, for maps of at most :data:`BOUNDARY_MAX_POINTS` points, the
verdicts and status codes the stability boundary is located from (2 bytes per
point), so its memory does not grow with the map beyond that (measured:
0.2 GB peak RSS for 1e8 points); :func:`stability_map` returns the whole map
in memory, so maps whose results would need more than :data:`MAX_MAP_BYTES`
are refused there.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import ParameterError
from ..status import PointStatus
from .verdict import Points, Verdicts, route_names

if TYPE_CHECKING:
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace

__all__ = ["Axis", "parse_axis", "resolution_problem", "stability_map", "write_map", "MapSummary", "classify_grid",
           "STATUS", "MAX_POINTS", "MAX_MAP_BYTES", "map_bytes"]

#: Meaning of the ``status`` codes of a map (:class:`~brakesqueal.status.PointStatus`).
STATUS = {int(s): s.meaning for s in PointStatus}
#: Maps larger than this need ``force=True`` (``--force``).
MAX_POINTS = 10**9
#: Largest memory [bytes] :func:`stability_map` may take for one map (:func:`map_bytes`); use :func:`write_map`
#: (bounded memory) beyond.
MAX_MAP_BYTES = 4 * 2**30
#: Largest map [points] whose stability boundary is located and stored.
BOUNDARY_MAX_POINTS = 16 * 10**6
#: Bisection steps of a map's boundary vertices: brackets of 2^-12 ~ 2e-4 of a grid step (the exact
#: arithmetic that decides points closer to the boundary is not needed for a figure, and costs seconds).
BOUNDARY_ITERATIONS = 12
#: Maps with more points than this store ``max_real`` and ``frequency`` as float32.
_FLOAT32_ABOVE = 2 * 10**7


@dataclass(frozen=True)
class Axis:
    """One sweep axis: ``num`` points from ``start`` to ``stop``, linear or logarithmic.

    Parameters
    ----------
    name : str
        The parameter the axis varies: a settable name of the
        :class:`~brakesqueal.model.parameters.ParameterSpace` (a model parameter such as ``Omega`` or
        a preset's auxiliary name such as ``mu`` or ``k_ip``).
    start, stop : float
        Range of the axis in the SI unit of ``name`` (e.g. rad/s for
        ``Omega``, N/m for ``k_ip``); finite, with ``stop > start``.
    num : int, optional
        Number of grid points of a map, including both ends (default 2, at
        least 2).  Paths (:func:`~brakesqueal.analysis.crossings.crossings`) only use the range.
    log : bool, optional
        Logarithmic spacing (:func:`numpy.logspace`; needs ``start > 0``)
        instead of linear (default ``False``).

    Raises
    ------
    ParameterError
        If a bound is not finite, the range is empty or reversed, a log axis
        has ``start <= 0`` or ``num < 2``.
    """

    name: str
    start: float
    stop: float
    num: int = 2
    log: bool = False

    def __post_init__(self) -> None:
        what = f"axis '{self.name}'"
        if not (math.isfinite(self.start) and math.isfinite(self.stop)):
            raise ParameterError(f"{what}: bounds must be finite; got {self.start!r}:{self.stop!r}")
        if not self.stop > self.start:
            raise ParameterError(f"{what}: empty or reversed range {self.start!r}:{self.stop!r} "
                                 "(STOP must be greater than START)")
        if self.log and self.start <= 0:
            raise ParameterError(f"{what}: a log axis needs positive bounds; got START = {self.start!r}")
        if self.num < 2:
            raise ParameterError(f"{what}: N must be at least 2; got {self.num}")
        problem = resolution_problem(self.start, self.stop, self.num, self.log)
        if problem:
            raise ParameterError(f"{what}: {problem}", parameter=self.name)

    def values(self) -> np.ndarray:
        """The grid points."""
        if self.log:
            return np.logspace(math.log10(self.start), math.log10(self.stop), self.num)
        return np.linspace(self.start, self.stop, self.num)

    def values_range(self, i0: int, i1: int) -> np.ndarray:
        """The grid points ``i0:i1``, equal to ``values()[i0:i1]`` without forming the whole axis.

        The element-wise arithmetic of :func:`numpy.linspace` / :func:`numpy.logspace`
        (``start + i * step``, the last point set to ``stop``; ``10**`` that for
        log axes) on the indices ``i0..i1-1`` only.

        Parameters
        ----------
        i0, i1 : int
            The range of indices, ``0 <= i0 <= i1 <= num``.

        Returns
        -------
        ndarray
            ``i1 - i0`` grid points.
        """
        if not 0 <= i0 <= i1 <= self.num:
            raise ValueError(f"axis '{self.name}': index range {i0}:{i1} outside 0:{self.num}")
        a, b = (math.log10(self.start), math.log10(self.stop)) if self.log else (self.start, self.stop)
        start, stop = np.float64(a), np.float64(b)
        delta = np.subtract(stop, start)
        div = self.num - 1
        step = delta / div
        y = np.arange(i0, i1, dtype=float)
        if step == 0:  # as numpy.linspace: subnormal steps
            y /= div
            y *= delta
        else:
            y *= step
        y += start
        if i1 == self.num and i1 > i0:
            y[-1] = stop
        return np.power(10.0, y) if self.log else y

    @property
    def ref(self) -> float:
        """A representative magnitude (geometric mean for log axes), used to scale polynomials."""
        if self.log:
            return math.sqrt(self.start * self.stop)
        return max(abs(self.start), abs(self.stop))


def resolution_problem(start: float, stop: float, num: int, log: bool) -> str | None:
    """Why ``num`` points from ``start`` to ``stop`` are finer than the floating-point resolution, or None.

    The rule of every axis, path and study range: the step (of ``log10`` on a
    log axis) must exceed 4 units in the last place of the bounds, so that the
    points are distinct, increasing numbers.  Ranges that are empty, reversed,
    not finite or (log) not positive are left to the caller's own checks.

    Parameters
    ----------
    start, stop : float
        The bounds.
    num : int
        Number of points including both ends (a path: 2).
    log : bool
        Logarithmic spacing.

    Returns
    -------
    str or None
        The reason (a clause for an error message), or None when the points are resolved.
    """
    if num < 2 or not (math.isfinite(start) and math.isfinite(stop) and stop > start) or (log and start <= 0):
        return None
    if log:
        t0, t1 = math.log10(start), math.log10(stop)
        eps = float(np.finfo(float).eps)
        ok = (t1 - t0) / (num - 1) > 4 * eps * (max(1.0, abs(t0), abs(t1)) + 1)
    else:
        ok = (stop - start) / (num - 1) > 4 * float(np.spacing(max(abs(start), abs(stop))))
    if ok:
        return None
    what = f"{num} points between" if num > 2 else "the bounds"
    return (f"{what} {start!r} and {stop!r} are closer than the floating-point resolution (they would not be "
            "distinct values); use " + ("fewer points or " if num > 2 else "") + "a wider range")


def parse_axis(text: str, *, with_num: bool = True) -> Axis:
    """Parse ``NAME=START:STOP:N[:log]`` (or ``NAME=START:STOP[:log]`` with ``with_num=False``), the form of the
    CLI's ``--x``, ``--y`` and ``--along`` options.

    Parameters
    ----------
    text : str
        The axis, e.g. ``"k_ip=1e5:1e10:400:log"``; ``START`` and ``STOP`` may be expressions (``2*pi``).
    with_num : bool
        Whether the number of points ``N`` is part of the form (maps) or not (paths).

    Returns
    -------
    Axis

    Raises
    ------
    ParameterError
        A malformed axis, bounds that are not finite or reversed, or fewer than 2 points (one line, naming it).
    """
    from ..model.expressions import evaluate

    name, sep, spec = text.partition("=")
    name = name.strip()
    form = "NAME=START:STOP:N[:log]" if with_num else "NAME=START:STOP[:log]"
    if not sep or not name.isidentifier():
        raise ParameterError(f"malformed axis {text!r}: expected {form}")
    parts = [p.strip() for p in spec.split(":")]
    log = bool(parts) and parts[-1].lower() in ("log", "lin", "linear")
    log_flag = log and parts[-1].lower() == "log"
    if log:
        parts = parts[:-1]
    if len(parts) != (3 if with_num else 2) or not all(parts):
        raise ParameterError(f"malformed axis {text!r}: expected {form}")
    start = evaluate(parts[0], {}, what=f"start of axis '{name}'")
    stop = evaluate(parts[1], {}, what=f"stop of axis '{name}'")
    num = 2
    if with_num:
        try:
            num = int(parts[2])
        except ValueError:
            raise ParameterError(f"axis '{name}': N must be an integer; got {parts[2]!r}") from None
    return Axis(name, start, stop, num, log_flag)


def map_bytes(points: int, eigen: bool) -> int:
    """Estimated peak memory [bytes] of computing a map in memory and writing it to NetCDF.

    Parameters
    ----------
    points : int
        Number of grid points.
    eigen : bool
        Whether ``max_real`` and ``frequency`` are stored.

    Returns
    -------
    int
        Twice the result arrays (``stable`` and ``status``, 1 byte each, and
        two float arrays, 8 bytes each or 4 above 2e7 points: the NetCDF3
        writer holds a converted copy of every variable until the file is
        closed) plus 256 MiB for the chunk buffers and the interpreter: a bound
        for :func:`stability_map` followed by ``to_netcdf``.  :func:`write_map`
        (the ``map`` command) does not hold the result arrays: its memory is
        bounded whatever the map's size (measured 0.2 GB peak RSS for a
        1e8-point map with ``max_real`` and ``frequency``; at most 2 bytes per
        point more for maps of at most :data:`BOUNDARY_MAX_POINTS` points, plus
        the boundary's location).
    """
    per = 2 + (2 * (4 if points > _FLOAT32_ABOVE else 8) if eigen else 0)
    return 2 * per * points + 2**28


def _check_axes(space: ParameterSpace, axes: list[Axis], force: bool, eigen: bool, in_memory: bool = True) -> None:
    for ax in axes:
        space.check_axis(ax.name)
    if len(axes) == 2 and axes[0].name == axes[1].name:
        raise ParameterError(f"both axes vary '{axes[0].name}'; choose two different parameters")
    n = math.prod(ax.num for ax in axes)
    if n > MAX_POINTS and not force:
        raise ParameterError(f"the map has {n:.3g} points (> {MAX_POINTS:.0e}); pass --force to compute it anyway")
    if not in_memory:
        from ..results import NC3_MAX_VAR_BYTES

        size = (4 if n > _FLOAT32_ABOVE else 8) if eigen else 1
        if n * size > NC3_MAX_VAR_BYTES:
            hint = "; --no-eigen stores 1 byte per point" if eigen else ""
            raise ParameterError(f"the map has {n:.3g} points: a variable of its NetCDF3 file would take "
                                 f"{n * size / 2**30:.3g} GiB, the format holds at most 4 GiB per variable "
                                 f"({NC3_MAX_VAR_BYTES // size:.4g} points{hint}); use fewer points or a sweep "
                                 "(brakesqueal sweep)")
        return
    need = map_bytes(n, eigen)
    if need > MAX_MAP_BYTES:
        hint = "; --no-eigen needs a fifth of it" if eigen else ""
        raise ParameterError(f"the map has {n:.3g} points: computing and writing it would take about "
                             f"{need / 2**30:.3g} GiB of memory (limit {MAX_MAP_BYTES / 2**30:g} GiB{hint}); use fewer "
                             "points, write_map (the map command, bounded memory) or a sweep (brakesqueal sweep)")


def classify_grid(engine: Engine, space: ParameterSpace, x: Axis, y: Axis) -> tuple[np.ndarray, str, str]:
    """Only the certified kernel's codes on the full grid (benchmarks, large maps).

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The parameter space.
    x, y : Axis
        The axes.

    Returns
    -------
    codes, outer, inner : ndarray, str, str
        ``codes[outer, inner]`` (uint8: 0 unstable, 1 stable, 2 uncertain,
        recomputed per point by :func:`stability_map`) and the axis names.

    Raises
    ------
    ParameterError
        If no compiled kernel applies (the closed-form route does not).
    """
    kern = engine.map_kernel(space, x.name, y.name)
    if kern is None:
        raise ParameterError("no compiled kernel for this map (no closed form for the model, a non-trivial silent "
                             "motion or non-rational dependence)")
    ax = {x.name: x, y.name: y}
    outer, inner = ax[kern.outer], ax[kern.inner]
    return kern.verdicts(outer.values(), inner.values()), kern.outer, kern.inner


@dataclass(frozen=True)
class _Plan:
    """How a map is computed: the engine, the axes in dimension order, the routes tried, the float type."""

    engine: Engine
    outer: Axis
    inner: Axis
    method: str
    ftype: type


def routes_text(closed: bool) -> str:
    """The ``method`` of a map or study: the routes in the order the dispatcher tries them (ASCII, NetCDF3)."""
    return "certified verdicts by the first route that decides (per point: variable 'route'): " + ", ".join(
        route_names()[1:])


def _plan(engine: Engine, space: ParameterSpace, x: Axis, y: Axis, force: bool, eigen: bool,
          in_memory: bool = True) -> _Plan:
    _check_axes(space, [x, y], force, eigen, in_memory)
    space.resolve({})
    closed = engine.closed_route(space, (x.name, y.name))
    kern = engine.map_kernel(space, x.name, y.name) if closed else None
    ax = {x.name: x, y.name: y}
    outer, inner = (ax[kern.outer], ax[kern.inner]) if kern else (y, x)
    ftype = np.float32 if outer.num * inner.num > _FLOAT32_ABOVE else np.float64
    return _Plan(engine, outer, inner, routes_text(closed), ftype)


_Block = tuple[int, int, int, int, "dict[str, np.ndarray]"]


def _blocks(n_o: int, n_i: int, points: int) -> Iterator[tuple[int, int, int, int]]:
    """Blocks ``(r0, r1, c0, c1)`` of at most ``max(points, 1)`` points in file order: whole outer rows, or
    pieces of one row when a row is longer (every block is contiguous in the row-major grid)."""
    points = max(1, points)
    if n_i <= points:
        rows = points // n_i
        for r0 in range(0, n_o, rows):
            yield r0, min(n_o, r0 + rows), 0, n_i
        return
    for r0 in range(n_o):
        for c0 in range(0, n_i, points):
            yield r0, r0 + 1, c0, min(n_i, c0 + points)


#: The quantities a map stores besides ``stable``, ``status``, ``max_real`` and ``frequency`` (by default; and
#: ``disk_stable`` for a model with massless pads' own modes, which a map's figure colours by default).
MAP_EXTRAS = ("carrier", "route")


def _rows(space: ParameterSpace, plan: _Plan, names: tuple[str, ...], chunk_points: int, modes: str = "all"
          ) -> Iterator[_Block]:
    """Yield ``(r0, r1, c0, c1, values)`` for blocks of the grid (bounded memory).

    A block is ``[r0:r1, c0:c1]`` of the ``(outer, inner)`` grid with at most
    ``chunk_points`` points: whole outer rows, or pieces of one row when a row
    is longer; each block is computed by the one grid evaluator of maps and sweeps
    (:func:`~.quantities.evaluate_block`: the dispatcher's verdicts and the quantities ``names``).
    """
    from .quantities import evaluate_block

    outer, inner = plan.outer, plan.inner
    n_o, n_i = outer.num, inner.num
    iv_all = inner.values() if n_i <= max(1, chunk_points) else None  # whole rows: the inner values formed once
    for r0, r1, c0, c1 in _blocks(n_o, n_i, chunk_points):
        # only this block's values: no array of an axis' length (a map may have very long axes)
        iv = iv_all if iv_all is not None else inner.values_range(c0, c1)
        ov = outer.values_range(r0, r1)
        pts = Points.of(space, {outer.name: ov, inner.name: iv}, grid=True)
        yield r0, r1, c0, c1, evaluate_block(plan.engine, space, pts, names, modes=modes)


def _names(eigen: bool, extras: tuple[str, ...] | None, engine: Engine | None = None
           ) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """``(all quantity names, the extras)`` of a map: ``max_real``/``frequency`` with ``eigen``, and the extras
    (default :data:`MAP_EXTRAS`, with ``disk_stable`` where the model's massless pads have modes of their own;
    quantities needing eigenvalues are left out without ``eigen``)."""
    from .quantities import has_pad_modes, quantity

    if extras is None:
        extras = MAP_EXTRAS + (("disk_stable",) if engine is not None and has_pad_modes(engine) else ())
    ex = tuple(extras)
    for n in ex:
        quantity(n)  # unknown names: one error naming the allowed ones
    ex = tuple(n for n in ex if n not in ("stable", "status", "max_real", "frequency") and (eigen or not
                                                                                              quantity(n).eigen))
    return (("max_real", "frequency") if eigen else ()) + ex, ex


def stability_map(engine: Engine, space: ParameterSpace, x: Axis, y: Axis, *, force: bool = False,
                  eigen: bool = True, chunk_points: int = 1 << 18, progress: Callable[[float], None] | None = None,
                  boundary: bool = True, modes: str = "all", quantities: tuple[str, ...] | None = None) -> Any:
    """Compute a stability map over two settable parameters of ``space``.

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The model, preset and overrides (:func:`brakesqueal.model.resolve_space`);
        tied names follow the axes.
    x, y : Axis
        The two axes (any ranges and signs; points with invalid parameters
        get status ``INVALID``).
    force : bool
        Allow more than :data:`MAX_POINTS` points (the memory limit
        :data:`MAX_MAP_BYTES` still holds).
    eigen : bool
        Compute ``max_real`` and ``frequency``; ``False`` only classifies
        and leaves both variables out of the result.
    chunk_points : int
        Points per chunk (bounds the temporary memory): whole outer rows, or
        pieces of one row when a row has more points.
    progress : callable, optional
        Called with the completed fraction after each chunk.
    boundary : bool
        Also locate the stability boundary as curves refined onto it by
        bisection (:func:`~.boundary.stability_boundary`; stored as
        ``boundary_<name>`` variables; only for maps of at most
        :data:`BOUNDARY_MAX_POINTS` points, to :data:`BOUNDARY_ITERATIONS` bisection steps).
    modes : {"all", "disk"}
        Judge every eigenvalue (default), or leave out the modes carried by a massless pad's own tangential
        rate (:func:`~.verdict.decide`).
    quantities : tuple of str, optional
        Further quantities to store (:mod:`~.quantities`; default :data:`MAP_EXTRAS`: ``carrier`` and
        ``route``); ``max_real`` and ``frequency`` follow ``eigen``.

    Returns
    -------
    StabilityMap
        See :class:`brakesqueal.results.StabilityMap`; ``stable`` is
        certified, ``status`` holds :class:`~brakesqueal.status.PointStatus`
        codes (``UNDECIDED`` marks points whose verdict could not be decided,
        e.g. exactly on a stability boundary); for ``OK``/``OK_NONTRIVIAL``
        points ``stable`` ⇔ ``max_real < 0``.  ``method`` names the routes,
        ``route`` and ``carrier`` say per point which decided and which mode carries the verdict.

    Raises
    ------
    ParameterError
        Unknown, tied or equal axes, more than :data:`MAX_POINTS` points
        without ``force``, or more memory than :data:`MAX_MAP_BYTES` (:func:`map_bytes`).
    """
    from ..results import StabilityMap

    from .quantities import attributes, quantity

    plan = _plan(engine, space, x, y, force, eigen)
    names, ex = _names(eigen, quantities, engine)
    n_o, n_i = plan.outer.num, plan.inner.num
    stable = np.zeros((n_o, n_i), dtype=bool)
    status = np.zeros((n_o, n_i), dtype=np.int8)
    max_real: np.ndarray | None = np.full((n_o, n_i), np.nan, dtype=plan.ftype) if eigen else None
    freq: np.ndarray | None = np.full((n_o, n_i), np.nan, dtype=plan.ftype) if eigen else None
    extra = {n: np.full((n_o, n_i), quantity(n).fill, dtype=plan.ftype if np.dtype(quantity(n).dtype).kind == "f"
                        else quantity(n).dtype) for n in ex}
    for r0, r1, c0, c1, v in _rows(space, plan, names, chunk_points, modes):
        stable[r0:r1, c0:c1] = v["stable"]
        status[r0:r1, c0:c1] = v["status"]
        for n in ex:
            extra[n][r0:r1, c0:c1] = v[n]
        if max_real is not None and freq is not None:
            max_real[r0:r1, c0:c1] = v["max_real"]
            freq[r0:r1, c0:c1] = v["frequency"]
        if progress is not None:
            progress(((r1 - 1) * n_i + c1) / (n_o * n_i))
    b = _boundary(space, plan, stable, status, modes) if boundary else None
    return StabilityMap.from_arrays(space, plan.outer, plan.inner, stable=stable, status=status, max_real=max_real,
                                    frequency=freq, method=plan.method, boundary=b,
                                    extra={n: (extra[n], attributes(n, engine)) for n in ex})


def _boundary(space: ParameterSpace, plan: _Plan, stable: np.ndarray, status: np.ndarray, modes: str = "all"
              ) -> Any:
    """The refined stability boundary of a map (``None`` above :data:`BOUNDARY_MAX_POINTS` points)."""
    from .boundary import stability_boundary
    from .points import evaluate

    if plan.outer.num * plan.inner.num > BOUNDARY_MAX_POINTS:
        return None

    def ev(values: dict[str, np.ndarray]) -> Verdicts:
        return evaluate(plan.engine, space, values, eigen=False, modes=modes)

    return stability_boundary(space, plan.outer, plan.inner, stable, status, iterations=BOUNDARY_ITERATIONS,
                              evaluator=ev)


@dataclass(frozen=True)
class MapSummary:
    """What :func:`write_map` reports about the map it wrote.

    Attributes
    ----------
    points : int
        Number of grid points.
    stable_fraction : float
        Fraction of points certified stable.
    method : str
        The route (the file's ``method`` attribute).
    outer, inner : Axis
        The axes in the file's dimension order.
    status_counts : dict of str to int
        Number of points of each status (:class:`~brakesqueal.status.PointStatus` meanings, only those
        that occur); the points of ``ok`` and ``ok_nontrivial_silent_motion`` have a verdict, the others none.
    unstable : int
        Number of points with a verdict ``unstable``.
    pad_only : int
        Number of unstable points whose disk modes are certified stable: only a massless pad's own
        (non-oscillatory) mode is unstable there (``disk_stable`` stored; 0 otherwise).
    """

    points: int
    stable_fraction: float
    method: str
    outer: Axis
    inner: Axis
    status_counts: dict[str, int] = field(default_factory=dict)
    unstable: int = 0
    pad_only: int = 0

    @property
    def stable(self) -> int:
        """Number of points certified stable."""
        return int(round(self.stable_fraction * self.points))

    @property
    def decided(self) -> int:
        """Number of points with a verdict (stable or unstable)."""
        return self.stable + self.unstable

    def text(self) -> str:
        """One line: stable and unstable points (percent of the decided ones) and the points without a verdict
        (:func:`~brakesqueal.status.verdict_counts_text`)."""
        from ..status import verdict_counts_text

        text = verdict_counts_text(self.points, self.stable, self.unstable, self.status_counts)
        if self.pad_only:
            text += (f"; {self.pad_only} of the unstable points only through a massless pad's own 0 Hz mode "
                     "(disk modes stable there: not squeal; variable 'disk_stable')")
        return text


def write_map(engine: Engine, space: ParameterSpace, x: Axis, y: Axis, path: str, *, force: bool = False,
              eigen: bool = True, chunk_points: int = 1 << 18, progress: Callable[[float], None] | None = None,
              boundary: bool = True, modes: str = "all", quantities: tuple[str, ...] | None = None) -> MapSummary:
    """Compute a stability map and write it to a NetCDF3 file block by block (memory bounded for any size).

    Same results and file content as ``stability_map(...).to_netcdf(path)``
    (read back with :func:`brakesqueal.results.open_map` or
    :func:`xarray.open_dataset`), with less time and memory: each block of
    ``chunk_points`` points (whole outer rows, or pieces of a longer row) is written to its place in the
    file (:class:`brakesqueal.results.MapFile`) as soon as it is computed;
    neither xarray nor the map's arrays are held (only ``stable`` and
    ``status`` of maps with at most :data:`BOUNDARY_MAX_POINTS` points, for the
    stability boundary).  There is no memory limit (:data:`MAX_MAP_BYTES`
    applies to :func:`stability_map`); a variable of the file holds at most
    4 GiB (:data:`~brakesqueal.results.NC3_MAX_VAR_BYTES`).

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The parameter space.
    x, y : Axis
        The axes.
    path : str
        The NetCDF file to write (the caller makes it atomic).
    force, eigen, chunk_points, progress, boundary, modes, quantities
        As :func:`stability_map`.

    Returns
    -------
    MapSummary

    Raises
    ------
    ParameterError
        As :func:`stability_map` (but no memory limit), or a variable of more
        than 4 GiB.
    """
    from ..results import MapFile
    from .quantities import attributes, quantity

    plan = _plan(engine, space, x, y, force, eigen, in_memory=False)
    names, ex = _names(eigen, quantities, engine)
    n_o, n_i = plan.outer.num, plan.inner.num
    # the boundary needs the verdicts and status codes of the whole grid (2 bytes per point, at most
    # BOUNDARY_MAX_POINTS points); nothing else of the map is held: each block of rows goes to the file at once
    keep = boundary and n_o * n_i <= BOUNDARY_MAX_POINTS
    stable = np.zeros((n_o, n_i), dtype=bool) if keep else None
    status = np.zeros((n_o, n_i), dtype=np.int8) if keep else None
    f = MapFile(path, space, plan.outer, plan.inner, eigen=eigen, float_dtype=plan.ftype, method=plan.method,
                boundary=keep, extras=tuple((n, quantity(n).dtype, attributes(n, engine)) for n in ex))
    n_stable = n_unstable = n_pad_only = 0
    counts = np.zeros(len(PointStatus), dtype=np.int64)
    try:
        for r0, r1, c0, c1, v in _rows(space, plan, names, chunk_points, modes):
            st, ss = v["stable"], v["status"]
            f.write_rows(r0, r1, st, ss, v.get("max_real"), v.get("frequency"), c0=c0, extra={n: v[n] for n in ex})
            n_stable += int(np.count_nonzero(st))
            codes = np.asarray(ss, dtype=np.int64).ravel()
            counts += np.bincount(codes, minlength=counts.size)[:counts.size]
            decided = (codes == PointStatus.OK) | (codes == PointStatus.OK_NONTRIVIAL)
            n_unstable += int(np.count_nonzero(decided & ~np.asarray(st, dtype=bool).ravel()))
            if "disk_stable" in v:
                n_pad_only += int(np.count_nonzero(~np.asarray(st, dtype=bool) & (v["disk_stable"] == 1)))
            if stable is not None and status is not None:
                stable[r0:r1, c0:c1] = st
                status[r0:r1, c0:c1] = ss
            if progress is not None:
                progress(((r1 - 1) * n_i + c1) / (n_o * n_i))
        if stable is not None and status is not None:
            b = _boundary(space, plan, stable, status, modes)
            if b is not None:
                f.write_boundary(b)
    except BaseException:
        f.abort()
        raise
    f.close()
    n = n_o * n_i
    return MapSummary(n, n_stable / n, plan.method, plan.outer, plan.inner,
                      {s.meaning: int(c) for s, c in zip(PointStatus, counts) if c}, n_unstable, n_pad_only)
