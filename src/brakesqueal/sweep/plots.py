"""Figures of a study's results (``brakesqueal plot STORE.zarr``): stability maps, slices and histograms.

The view follows the store's dimensions unless asked otherwise (:func:`sweep_view`):

* a grid of two or more axes: the stability map of ``brakesqueal map --plot``
  (:func:`brakesqueal.plotting.plot_map_arrays`: green stable, red unstable,
  hatched without a verdict) over two axes, by default the two with the most
  points, the later of them horizontal (as ``map`` draws its inner axis); the
  other axes at the grid value nearest to ``at`` (default: their first value),
  named in the title;
* a grid of one axis (or ``kind="slice"``): a quantity (``max_real`` when it was
  computed) along the axis, its stable and unstable stretches shaded;
* a sampled study (random or Latin hypercube): histograms of the computed
  quantities, stacked by verdict, with the fraction unstable in the title
  (``kind="map"``: the samples over two sampled parameters).

A store whose run was stopped is drawn as far as it is computed: the points of
chunks without a completion marker are drawn grey as "not computed yet" (left
out of the histograms of quantities) and counted in :attr:`SweepPlot.not_computed`;
nothing is drawn as stable or unstable without a verdict.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import ParameterError
from ._figures import draw, marked_chunks, scale_log, slice_quantity

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.figure import Figure

__all__ = ["KINDS", "SweepView", "SweepPlot", "open_store", "parse_at", "sweep_view", "plot_view", "plot_sweep",
           "default_figure_path"]

#: The views of :func:`sweep_view`: a map over two axes, a slice along one, histograms.
KINDS = ("map", "slice", "hist")


# ---------------------------------------------------------------- the view
@dataclass(frozen=True)
class SweepView:
    """What :func:`plot_view` draws: the store, the kind of figure, its axes and the values of the other axes.

    Attributes
    ----------
    data : xarray.Dataset
        The study's results (lazily read from the store).
    store : pathlib.Path or None
        The store (None: a dataset computed in memory).
    kind : {"map", "slice", "hist"}
        The figure.
    x, y : str or None
        Horizontal and vertical axis of a map; ``x`` the axis of a slice, or the sampled
        parameter of a histogram (None: histograms of the quantities).
    color : str
        ``"verdict"`` or a computed quantity (``max_real``, ``frequency``, ``margin``, ``critical_speed``).
    at : dict of str to float
        The grid value drawn of every other axis of a map or slice.
    index : dict of str to int
        Its index on the axis.
    asked : dict of str to float
        The values given with ``at`` (before taking the nearest grid value).
    quantities : tuple of str
        The store's continuous quantities.
    sampled : bool
        Whether the study is sampled (dimension ``sample``) rather than a grid.
    """

    data: xr.Dataset
    store: Path | None
    kind: str
    x: str | None
    y: str | None
    color: str
    at: dict[str, float] = field(default_factory=dict)
    index: dict[str, int] = field(default_factory=dict)
    asked: dict[str, float] = field(default_factory=dict)
    quantities: tuple[str, ...] = ()
    sampled: bool = False

    @property
    def axes(self) -> tuple[str, ...]:
        """The grid axes, or the sampled parameters."""
        return _axes(self.data, self.sampled)


@dataclass
class SweepPlot:
    """A figure of a study's results (:func:`plot_view`).

    Attributes
    ----------
    figure : matplotlib.figure.Figure
        The figure.
    view : SweepView
        What it shows.
    points : int
        Points drawn (or counted in the histograms).
    stable, unstable : int
        Of them, computed points with the verdict stable / unstable.
    status_counts : dict of str to int
        Points per status meaning (``not_computed`` included).
    not_computed : int
        Points drawn that are not computed yet.
    chunks : tuple of (int, int) or None
        Chunks with a completion marker and all chunks of the store (None without a store).
    notes : list of str
        One-line remarks for the user: an incomplete store, the nearest grid value taken, ...
    """

    figure: Figure
    view: SweepView
    points: int
    stable: int
    unstable: int
    status_counts: dict[str, int]
    not_computed: int = 0
    chunks: tuple[int, int] | None = None
    notes: list[str] = field(default_factory=list)

    def text(self) -> str:
        """One line: what the figure shows and the verdicts of its points."""
        from ..status import verdict_counts_text

        v = self.view
        what = {"map": f"map of {v.y} vs {v.x}", "slice": f"{slice_quantity(v) or 'verdict'} along {v.x}",
                "hist": f"histograms of {v.x or v.color}"}[v.kind]
        if v.kind == "hist" and v.x is None and v.color == "verdict":
            what = "histograms of " + (", ".join(v.quantities) or "the verdicts")
        if v.kind == "map" and v.color != "verdict":
            what += f" coloured by {v.color}"
        at = ", ".join(f"{n} = {val:.6g}" for n, val in v.at.items())
        verdicts = verdict_counts_text(self.points, self.stable, self.unstable, self.status_counts)
        return f"{what}{' at ' + at if at else ''}; {verdicts}"


def _axes(ds: xr.Dataset, sampled: bool) -> tuple[str, ...]:
    if not sampled:
        return tuple(str(d) for d in ds["stable"].dims)
    return tuple(str(c) for c in ds.coords if c != "sample" and ds[c].dims == ("sample",))


def default_figure_path(store: str | os.PathLike[str]) -> Path:
    """The figure ``brakesqueal plot STORE`` writes without ``--out``: the store's name with ``.png``, beside it.

    Parameters
    ----------
    store : str or path-like
        The store (``results/fig2.zarr``).

    Returns
    -------
    pathlib.Path
        E.g. ``results/fig2.png``.
    """
    p = Path(os.fspath(store).rstrip("/") or ".")
    return p.with_suffix(".png") if p.suffix else p.with_name(p.name + ".png")


def open_store(store: str | os.PathLike[str]) -> tuple[xr.Dataset, Path]:
    """Open a study's store for plotting (:func:`brakesqueal.sweep.open_sweep`), with one-line errors.

    Parameters
    ----------
    store : str or path-like
        A Zarr store written by :func:`brakesqueal.sweep.sweep` (``brakesqueal sweep``).

    Returns
    -------
    (xarray.Dataset, pathlib.Path)
        The results (lazy) and the store's path.

    Raises
    ------
    ParameterError
        ``store`` does not exist or is not a sweep store.
    StoreError
        The store's metadata are damaged.
    """
    from ..errors import BrakesquealError
    from .runner import open_sweep

    p = Path(os.fspath(store))
    what = f"STORE '{os.fspath(store)}'"
    if not p.exists():
        raise ParameterError(f"{what} does not exist; give a Zarr store written by brakesqueal sweep")
    if not p.is_dir() or not (p / "zarr.json").is_file():
        raise ParameterError(f"{what} is not a sweep store (a directory with zarr.json written by brakesqueal "
                             "sweep)")
    try:
        ds = open_sweep(p)
    except BrakesquealError:
        raise
    except Exception as exc:  # noqa: BLE001 - whatever zarr/xarray raise for a foreign or broken store: one line
        first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
        raise ParameterError(f"{what} cannot be read as a sweep store: {first}") from None
    if "stable" not in ds.data_vars or "status" not in ds.data_vars or "study_hash" not in ds.attrs:
        raise ParameterError(f"{what} is a Zarr store but not one written by brakesqueal sweep (no study, "
                             "stable or status)")
    return ds, p


def parse_at(items: Sequence[str]) -> dict[str, str]:
    """``--at NAME=VALUE`` options as ``{NAME: VALUE}`` (the values are checked by :func:`sweep_view`).

    Parameters
    ----------
    items : sequence of str
        ``["Omega=16*pi", "k_ip=1e8"]``.

    Returns
    -------
    dict of str to str

    Raises
    ------
    ParameterError
        An item without ``=``, an empty name or value, or a name given twice.
    """
    out: dict[str, str] = {}
    for item in items:
        name, sep, value = item.partition("=")
        name, value = name.strip(), value.strip()
        if not sep or not name or not value:
            raise ParameterError(f"--at must be NAME=VALUE (an axis of the store and a value on it, e.g. "
                                 f"Omega=50); got {item!r}")
        if name in out:
            raise ParameterError(f"--at {name} is given twice ({name}={out[name]} and {name}={value})")
        out[name] = value
    return out


def _choices(name: str, allowed: Sequence[str]) -> str:
    from ..suggest import did_you_mean

    return f"{', '.join(allowed) if allowed else 'none'}; got {name!r}{did_you_mean(name, allowed)}"


def _longest(ds: xr.Dataset, names: Sequence[str]) -> str:
    """The axis with the most points (ties: the later one)."""
    return max(reversed(names), key=lambda n: ds.sizes[n])


def sweep_view(store: str | os.PathLike[str] | xr.Dataset, *, kind: str | None = None, x: str | None = None,
               y: str | None = None, color: str = "verdict",
               at: Mapping[str, float | str] | None = None) -> SweepView:
    """Choose and check what to draw of a study's results (reads the coordinates only).

    Parameters
    ----------
    store : str, path-like or xarray.Dataset
        A sweep store, or the dataset :func:`brakesqueal.sweep.sweep` returned.
    kind : {"map", "slice", "hist"}, optional
        Default: ``map`` for grids of two or more axes, ``slice`` for one axis,
        ``hist`` for sampled studies.
    x, y : str, optional
        Axes of a map (default: the two longest, the later one horizontal) or of a
        slice (``x``, default the longest); for histograms of a sampled study, ``x``
        is a sampled parameter (the samples over it, stacked by verdict).
    color : str
        ``"verdict"`` or a quantity the study computed (``max_real``, ``frequency``,
        ``margin``, ``critical_speed``): the map's colours, the slice's curve, the histogram.
    at : mapping of str to float or str, optional
        Values of the axes not drawn (numbers or expressions such as ``"16*pi"``); the
        nearest grid value is drawn.  Axes not given are drawn at their first value.

    Returns
    -------
    SweepView

    Raises
    ------
    ParameterError
        One line naming the option and the allowed values: not a store, an unknown
        kind, axis or quantity, a value outside its axis.
    """
    if isinstance(store, (str, os.PathLike)):
        ds, path = open_store(store)
        src = f"'{os.fspath(store)}'"
    else:
        ds, path, src = store, None, "the study"
    sampled = ds["stable"].dims == ("sample",)
    axes = _axes(ds, sampled)
    from ..analysis.quantities import QUANTITIES

    dims = ds["stable"].dims
    quantities = tuple(str(v) for v in ds.data_vars if v not in ("stable", "status") and ds[v].dims == dims
                       and np.issubdtype(ds[v].dtype, np.floating))
    colors = ("verdict", *quantities)
    if color not in colors:
        if color in QUANTITIES and color not in ds.data_vars:
            raise ParameterError(f"--color {color}: not computed in {src} (its study's [compute] quantities); "
                                 f"allowed: {', '.join(colors)}")
        raise ParameterError(f"--color must be one of {_choices(color, colors)}")
    grid_kinds = ("slice", "hist") if len(axes) == 1 and not sampled else KINDS
    allowed_kinds = ("hist", "map") if sampled and len(axes) >= 2 else ("hist",) if sampled else grid_kinds
    if kind is None:
        kind = "hist" if sampled else "slice" if len(axes) == 1 else "map"
    if kind not in allowed_kinds:
        why = ("a sampled study has no grid axes" if sampled else
               f"{src} has one axis ({axes[0]})" if len(axes) == 1 else "")
        raise ParameterError(f"--kind must be one of {', '.join(allowed_kinds)} for {src}"
                             + (f" ({why})" if why else "") + f"; got {kind!r}")
    what_axes = "sampled parameters" if sampled else "axes"
    for opt, name in (("--x", x), ("--y", y)):
        if name is not None and name not in axes:
            raise ParameterError(f"{opt} must be one of the {what_axes} of {src}: {_choices(name, axes)}")
    if y is not None and kind != "map":
        raise ParameterError(f"--y applies to --kind map only (the figure here is --kind {kind})")
    if kind == "hist" and not sampled and not quantities:
        raise ParameterError(f"--kind hist draws the histograms of quantities; {src} has only the verdict (add "
                             "max_real, frequency or margin to its study's [compute] quantities); allowed here: "
                             f"--kind {' or '.join(k for k in allowed_kinds if k != 'hist')}")
    if kind == "hist" and x is not None:
        if not sampled:
            raise ParameterError("--x with --kind hist names a sampled parameter; a grid study's histograms are "
                                 "of its quantities (--color)")
        if color != "verdict":
            raise ParameterError("--kind hist: give --x (the samples over a parameter) or --color (a quantity), "
                                 "not both")
    if kind == "map":
        if x is not None and x == y:
            raise ParameterError(f"--x and --y must be different axes; both are {x!r}")
        if sampled:
            x = x or next(a for a in axes if a != y)
            y = y or next(a for a in axes if a != x)
        else:
            if x is None and y is None:
                y, x = [a for a in axes if a in _two_longest(ds, axes)]
            elif x is None:
                x = _longest(ds, [a for a in axes if a != y])
            elif y is None:
                y = _longest(ds, [a for a in axes if a != x])
    elif kind == "slice":
        x = x or _longest(ds, axes)
    drawn = {a for a in (x, y) if a is not None} if kind != "hist" else set(axes)
    view_at, index, asked = _resolve_at(ds, src, axes if not sampled else (), drawn, dict(at or {}), kind, sampled)
    return SweepView(ds, path, kind, x, y, color, view_at, index, asked, quantities, sampled)


def _two_longest(ds: xr.Dataset, axes: Sequence[str]) -> set[str]:
    """The two axes with the most points (ties: the later axes)."""
    ranked = sorted(range(len(axes)), key=lambda i: (ds.sizes[axes[i]], i), reverse=True)
    return {axes[i] for i in ranked[:2]}


def _resolve_at(ds: xr.Dataset, src: str, axes: Sequence[str], drawn: set[str], at: dict[str, float | str],
                kind: str, sampled: bool) -> tuple[dict[str, float], dict[str, int], dict[str, float]]:
    """The grid value (and index) drawn of every axis not drawn: nearest to ``at``, else the first value."""
    from ..model.expressions import evaluate

    if at and (sampled or kind == "hist"):
        raise ParameterError("--at applies to the grid axes of a map or slice"
                             + (" (a sampled study has none)" if sampled else f", not to --kind {kind}"))
    others = [a for a in axes if a not in drawn]
    values: dict[str, float] = {}
    index: dict[str, int] = {}
    asked: dict[str, float] = {}
    for name, raw in at.items():
        if name not in others:
            if name in drawn:
                raise ParameterError(f"--at {name}: {name} is an axis of the figure; --at fixes the other axes: "
                                     f"{', '.join(others) or 'none'}")
            raise ParameterError(f"--at must name an axis of {src} not drawn: {_choices(name, others)}")
        v = float(raw) if not isinstance(raw, str) else evaluate(raw, {}, what=f"--at {name}")
        grid = np.asarray(ds[name].values, dtype=float)
        lo, hi = float(grid.min()), float(grid.max())
        tol = 1e-9 * max(abs(lo), abs(hi), 1e-300)
        if not (math.isfinite(v) and lo - tol <= v <= hi + tol):
            u = ds[name].attrs.get("units", "")
            raise ParameterError(f"--at {name}={raw}: outside the axis {name} [{lo:.6g}, {hi:.6g}]"
                                 f"{' ' + u if u and u != '1' else ''} ({grid.size} grid values)")
        if scale_log(ds, name) and v > 0 and lo > 0:
            i = int(np.argmin(np.abs(np.log(grid) - math.log(v))))
        else:
            i = int(np.argmin(np.abs(grid - v)))
        values[name], index[name], asked[name] = float(grid[i]), i, v
    for name in others:
        if name not in values:
            values[name], index[name] = float(ds[name].values[0]), 0
    ordered = [a for a in axes if a in values]
    return {a: values[a] for a in ordered}, {a: index[a] for a in ordered}, asked


# ---------------------------------------------------------------- drawing
def plot_view(view: SweepView) -> SweepPlot:
    """Draw a view of a study's results.

    Parameters
    ----------
    view : SweepView
        From :func:`sweep_view`.

    Returns
    -------
    SweepPlot
        The figure, the counts of its points and notes (an incomplete store, the grid values taken).
    """
    marked, n_chunks = marked_chunks(view)
    d = draw(view, marked)
    chunks = None if n_chunks is None else (n_chunks if marked is None else len(marked), n_chunks)
    res = SweepPlot(d.figure, view, d.points, d.stable, d.unstable, d.status_counts, d.not_computed, chunks,
                    [*_at_notes(view), *d.notes])
    if (res.chunks is not None and res.chunks[0] < res.chunks[1]) or res.not_computed:
        res.notes.append(_incomplete_note(view, res))
    return res


def plot_sweep(store: str | os.PathLike[str] | xr.Dataset, *, kind: str | None = None, x: str | None = None,
               y: str | None = None, color: str = "verdict",
               at: Mapping[str, float | str] | None = None) -> SweepPlot:
    """A figure of a study's results: a stability map, a slice along one axis or histograms.

    ``plot_view(sweep_view(...))``; the figure is :attr:`SweepPlot.figure`.

    Parameters
    ----------
    store : str, path-like or xarray.Dataset
        A sweep store, or the dataset :func:`brakesqueal.sweep.sweep` returned.
    kind : {"map", "slice", "hist"}, optional
        As for :func:`sweep_view`.
    x, y : str, optional
        As for :func:`sweep_view`.
    color : str
        As for :func:`sweep_view`.
    at : mapping of str to float or str, optional
        As for :func:`sweep_view`.

    Returns
    -------
    SweepPlot

    Examples
    --------
    >>> fig = plot_sweep("fig2-omega.zarr", at={"Omega": 50}).figure   # doctest: +SKIP
    """
    return plot_view(sweep_view(store, kind=kind, x=x, y=y, color=color, at=at))


def _at_notes(view: SweepView) -> list[str]:
    notes = []
    for name, v in view.at.items():
        n = view.data.sizes[name]
        if name in view.asked:
            a = view.asked[name]
            if not math.isclose(a, v, rel_tol=1e-12, abs_tol=0.0):
                notes.append(f"--at {name}={a:.6g}: drawn at the nearest grid value {name} = {v:.6g}")
        else:
            grid = view.data[name].values
            notes.append(f"{name} is drawn at its first grid value {v:.6g} ({n} values from {float(grid[0]):.6g} "
                         f"to {float(grid[-1]):.6g}; --at {name}=VALUE chooses another)")
    return notes


def _incomplete_note(view: SweepView, res: SweepPlot) -> str:
    from .lock import lock_holder

    where = f"store '{view.store}'" if view.store is not None else "the study"
    chunks = f": {res.chunks[0]} of {res.chunks[1]} chunks computed" if res.chunks is not None else ""
    of_quantities = view.kind == "hist" and view.x is None and (view.color != "verdict" or bool(view.quantities))
    shown = "left out of the histograms" if of_quantities else "drawn grey"
    text = (f"{where} is incomplete{chunks}; " + (f"the {res.not_computed} points of the figure not computed yet "
                                                    f"are {shown}" if res.not_computed else
                                                    "the points of the figure are all computed"))
    holder = lock_holder(view.store) if view.store is not None else None
    if holder is not None:
        return text + f"; a run is writing it ({holder.describe()})"
    study = str(view.data.attrs.get("study_file", ""))
    study = study if study and study != "<dict>" else "STUDY"
    return text + f"; run its study again to resume (brakesqueal sweep {study}" + (
        f" --out {view.store})" if view.store is not None else ")")
