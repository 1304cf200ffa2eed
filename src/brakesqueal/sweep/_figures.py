"""Reading and drawing for :mod:`brakesqueal.sweep.plots`: the points of a view, and its figure.

Figures reuse the package's map figure (:func:`~brakesqueal.plotting.plot_map_arrays`, what
``map --plot`` draws) and its conventions: green stable, red unstable (squeal), hatched without a
verdict, grey for points of a store not computed yet (chunks without a completion marker); axis
labels with symbols and units (:mod:`brakesqueal.labels`); legends above the axes.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..plotting import styled
from ..status import DECIDED, PointStatus

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from .plots import SweepView

__all__ = ["STABLE", "UNSTABLE", "NOT_COMPUTED", "LABELS", "Drawn", "marked_chunks", "draw", "label",
           "slice_quantity", "hist_edges", "scale_log"]

#: Colours of the verdicts: those of :func:`brakesqueal.plotting.plot_map_arrays` (maps), and the grey of points
#: not computed yet.
STABLE, UNSTABLE, NOT_COMPUTED = "#c8e6c9", "#f4c7c3", "0.82"
#: Face colours of the categories of :func:`_categories` (stable, unstable, without a verdict: hatched, not computed).
_FACE = (STABLE, UNSTABLE, "white", NOT_COMPUTED)
#: Labels of the categories, as the maps' legend.
LABELS = ("stable", "unstable (squeal)", "no verdict (see status)", "not computed yet")
#: Symbols of stored quantities without an entry of their own in :data:`brakesqueal.labels.QUANTITIES`.
_QUANTITY_LABEL = {"margin": "damping_ratio", "critical_speed": "Omega_crit"}
_NC = int(PointStatus.NOT_COMPUTED)
#: Points read at once by a histogram (slabs of whole chunks along the first dimension).
_SLAB_POINTS = 4_000_000


@dataclass
class Drawn:
    """A figure and the counts of its points (see :class:`~brakesqueal.sweep.plots.SweepPlot`).

    Attributes
    ----------
    figure : matplotlib.figure.Figure
        The figure.
    points, stable, unstable, not_computed : int
        Points drawn; of them stable, unstable, not computed yet.
    status_counts : dict of str to int
        Points per status meaning.
    notes : list of str
        Remarks (an axis drawn from every k-th point).
    """

    figure: Figure
    points: int
    stable: int
    unstable: int
    status_counts: dict[str, int]
    not_computed: int
    notes: list[str] = field(default_factory=list)


def draw(view: SweepView, marked: set[int] | None) -> Drawn:
    """Read the points of ``view`` and draw its figure.

    Parameters
    ----------
    view : SweepView
        What to draw.
    marked : set of int or None
        Chunks with a completion marker (:func:`marked_chunks`; None: all).

    Returns
    -------
    Drawn
    """
    if view.kind == "map":
        return _sample_map(view, marked) if view.sampled else _grid_map(view, marked)
    if view.kind == "slice":
        return _slice(view, marked)
    return _hist(view, marked)


# ---------------------------------------------------------------- reading
def marked_chunks(view: SweepView) -> tuple[set[int] | None, int | None]:
    """Chunks with a completion marker (None: all of them, or no store) and the number of chunks."""
    n = view.data.attrs.get("n_chunks")
    if view.store is None or not isinstance(n, (int, np.integer)):
        return None, None
    from .store import MARKERS, completed_chunks

    d = view.store / MARKERS
    try:
        names = os.listdir(d)
    except OSError:
        return set(), int(n)
    if sum(1 for f in names if f.endswith(".json") and f[:-5].isdigit()) >= n:
        return None, int(n)  # every chunk is marked (their checksums are verified by --status and resume)
    return {c for c, m in completed_chunks(view.store).items() if m is not None and 0 <= c < n}, int(n)


def _chunk_ids(shape: Sequence[int], chunks: Sequence[int], sel: Sequence[int | np.ndarray]) -> np.ndarray:
    """Chunk number (C order over the chunk grid) of every selected point: outer product of the array selections."""
    grid = [-(-s // c) for s, c in zip(shape, chunks)]
    k = sum(1 for s in sel if np.ndim(s))
    ids: Any = 0
    pos = 0
    for d, (s, c) in enumerate(zip(sel, chunks)):
        stride = math.prod(grid[d + 1:])
        part = np.asarray(s, dtype=np.int64) // c
        if part.ndim:
            shape_b = [1] * k
            shape_b[pos] = -1
            part = part.reshape(shape_b)
            pos += 1
        ids = ids + part * stride
    return np.broadcast_to(np.asarray(ids, dtype=np.int64), [np.size(s) for s in sel if np.ndim(s)])


def _indices(s: int | np.ndarray | slice, n: int) -> int | np.ndarray:
    return np.arange(n)[s] if isinstance(s, slice) else s


def _read(view: SweepView, sel: Mapping[str, int | np.ndarray | slice], names: Sequence[str],
          marked: set[int] | None) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """The variables ``names`` (and ``stable``, ``status``) at an outer selection, in dimension order, and the mask
    of points not computed yet (status ``NOT_COMPUTED`` or a chunk without marker): those get ``stable`` False,
    status ``NOT_COMPUTED`` and NaN quantities."""
    ds = view.data
    dims = [str(d) for d in ds["stable"].dims]
    wanted = list(dict.fromkeys(["stable", "status", *names]))
    sub = ds[wanted].isel({d: sel[d] for d in dims if d in sel}).compute()
    out = {n: np.asarray(sub[n].values) for n in wanted}
    missing = out["status"] == _NC
    chunk_shape = ds.attrs.get("chunk_shape")
    if marked is not None and chunk_shape is not None and len(chunk_shape) == len(dims):
        full = [_indices(sel.get(d, slice(None)), ds.sizes[d]) for d in dims]
        ids = _chunk_ids([ds.sizes[d] for d in dims], [int(c) for c in chunk_shape], full)
        missing = missing | ~np.isin(ids, np.fromiter(marked, dtype=np.int64, count=len(marked)))
    out["stable"] = np.where(missing, False, out["stable"].astype(bool))
    out["status"] = np.where(missing, _NC, out["status"]).astype(np.int8)
    for n in names:
        if n not in ("stable", "status"):
            out[n] = np.where(missing, np.nan, out[n].astype(float))
    return out, missing


def _categories(stable: np.ndarray, status: np.ndarray) -> np.ndarray:
    """0 stable, 1 unstable, 2 without a verdict, 3 not computed yet."""
    decided = np.isin(status, [int(s) for s in DECIDED])
    return np.where(status == _NC, 3, np.where(~decided, 2, np.where(stable, 0, 1))).astype(np.int8)


def _counts(stable: np.ndarray, status: np.ndarray) -> tuple[int, int, dict[str, int]]:
    cat = _categories(stable, status)
    counts = {s.meaning: int(np.count_nonzero(status == int(s))) for s in PointStatus}
    return int(np.count_nonzero(cat == 0)), int(np.count_nonzero(cat == 1)), {k: v for k, v in counts.items() if v}


# ---------------------------------------------------------------- the views
def slice_quantity(view: SweepView) -> str | None:
    """The quantity a slice draws as its curve: ``color``, or ``max_real`` for the verdict (None: not computed)."""
    if view.color != "verdict":
        return view.color
    return "max_real" if "max_real" in view.quantities else None


def _value_text(ds: xr.Dataset, name: str, value: float) -> str:
    from ..labels import symbol

    u = str(ds[name].attrs.get("units", ""))
    return f"${symbol(name)}$ = {value:.4g}" + (f" {u}" if u and u != "1" else "")


def _title(view: SweepView, head: str) -> list[str]:
    """The pieces of a title (:func:`_suptitle` wraps between them): what, at which values of the other axes, the
    preset or model."""
    at = [_value_text(view.data, n, v) for n, v in view.at.items()]
    at = [("at " if i == 0 else "") + a + ("," if i < len(at) - 1 else "") for i, a in enumerate(at)]
    space = str(view.data.attrs.get("space", ""))
    return [head, *at, *([f"({space})"] if space else [])]


def _suptitle(fig: Figure, pieces: list[str]) -> None:
    """The figure's title, the pieces joined by spaces and wrapped between them so that no line is wider than the
    figure (a title is never clipped)."""
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    text = fig.suptitle("", fontsize="medium")
    lines: list[str] = []
    for piece in pieces:
        trial = f"{lines[-1]} {piece}" if lines else piece
        text.set_text(trial)
        if lines and text.get_window_extent(renderer).width <= 0.98 * fig.bbox.width:
            lines[-1] = trial
        elif lines:
            lines.append(piece)
        else:
            lines = [piece]
    text.set_text("\n".join(lines))


def _map_selection(view: SweepView) -> tuple[dict[str, int | np.ndarray], list[str]]:
    """The outer selection of a map (every k-th point of a long axis, as ``map --plot``) and notes."""
    from ..results import MAX_PLOT_POINTS, plot_indices

    sel: dict[str, int | np.ndarray] = dict(view.index)
    notes = []
    for name in (view.x, view.y):
        if name is None:
            continue
        n = view.data.sizes[name]
        idx = plot_indices(n, MAX_PLOT_POINTS)
        sel[name] = idx
        if n > MAX_PLOT_POINTS:
            notes.append(f"{name} has {n} points: every {int(idx[1])}-th is drawn (the figure has fewer pixels)")
    return sel, notes


def _grid_map(view: SweepView, marked: set[int] | None) -> Drawn:
    from ..labels import symbol
    from ..plotting import MAP_COLORS, map_title

    ds, xn, yn = view.data, view.x, view.y
    assert xn is not None and yn is not None
    sel, notes = _map_selection(view)
    names = [] if view.color == "verdict" else [view.color]
    data, missing = _read(view, sel, names, marked)
    dims = [d for d in ds["stable"].dims if d in (xn, yn)]
    flip = dims != [yn, xn]  # the arrays' axes are in the store's order: make them (y, x)

    def yx(a: np.ndarray) -> np.ndarray:
        return a.T if flip else a

    stable, status, miss = yx(data["stable"]), yx(data["status"]), yx(missing)
    field = yx(data[view.color]) if names else None
    xs = np.asarray(ds[xn].values[sel[xn]], dtype=float)
    ys = np.asarray(ds[yn].values[sel[yn]], dtype=float)
    space = str(ds.attrs.get("space", ""))
    title = [map_title(space, xn, yn)] if space and not view.at else _title(view, f"${symbol(yn)}$ vs ${symbol(xn)}$")
    color = view.color if view.color in MAP_COLORS else "frequency"  # another quantity: a linear colour scale
    fig = _map_figure(ds, (xn, xs), (yn, ys), stable, status, miss, title, color, field, view.color)
    s, u, counts = _counts(stable, status)
    return Drawn(fig, int(stable.size), s, u, counts, int(np.count_nonzero(miss)), notes=notes)


def _slice(view: SweepView, marked: set[int] | None) -> Drawn:
    from ..labels import symbol

    ds, xn = view.data, view.x
    assert xn is not None
    sel, notes = _map_selection(view)
    q = slice_quantity(view)
    data, missing = _read(view, sel, [q] if q else [], marked)
    xs = np.asarray(ds[xn].values[sel[xn]], dtype=float)
    fig = _slice_figure(ds, xn, xs, _categories(data["stable"], data["status"]), data[q] if q else None, q,
                        _title(view, f"Stability along ${symbol(xn)}$"))
    s, u, counts = _counts(data["stable"], data["status"])
    return Drawn(fig, int(xs.size), s, u, counts, int(np.count_nonzero(missing)), notes=notes)


def _sample_map(view: SweepView, marked: set[int] | None) -> Drawn:
    from ..labels import symbol

    ds, xn, yn = view.data, view.x, view.y
    assert xn is not None and yn is not None
    names = [] if view.color == "verdict" else [view.color]
    data, missing = _read(view, {}, names, marked)
    xs, ys = (np.asarray(ds[n].values, dtype=float) for n in (xn, yn))
    cat = _categories(data["stable"], data["status"])
    fig = _samples_figure(ds, (xn, xs), (yn, ys), cat, data[view.color] if names else None, view.color,
                          _title(view, f"${symbol(yn)}$ vs ${symbol(xn)}$, {xs.size} samples"))
    s, u, counts = _counts(data["stable"], data["status"])
    return Drawn(fig, int(xs.size), s, u, counts, int(np.count_nonzero(missing)))


def _slabs(view: SweepView) -> list[slice]:
    """Slabs of whole chunks along the first dimension, each of at most about ``_SLAB_POINTS`` points."""
    ds = view.data
    dims = ds["stable"].dims
    n0 = ds.sizes[dims[0]]
    row = math.prod(ds.sizes[d] for d in dims[1:])
    cs = ds.attrs.get("chunk_shape")
    c0 = int(cs[0]) if cs is not None and len(cs) == len(dims) else 1
    step = max(c0, (_SLAB_POINTS // max(row, 1)) // c0 * c0)
    return [slice(a, min(a + step, n0)) for a in range(0, n0, step)]


def _hist(view: SweepView, marked: set[int] | None) -> Drawn:
    """Histograms: of the quantities (or of one, ``color``), or of the samples over a sampled parameter (``x``),
    stacked by verdict; read in slabs of whole chunks (two passes: the ranges, then the counts)."""
    ds = view.data
    if view.x is not None:
        panels = [view.x]
    elif view.color != "verdict":
        panels = [view.color]
    else:
        panels = list(view.quantities) or list(view.axes)  # a grid without quantities is refused by sweep_view
    qs = [p for p in panels if p in ds.data_vars]
    dim0 = str(ds["stable"].dims[0])

    def values(data: dict[str, np.ndarray], p: str, sl: slice) -> np.ndarray:
        v = data[p] if p in qs else np.asarray(ds[p].isel({dim0: sl}).values, dtype=float)
        return np.asarray(v, dtype=float).ravel()

    rng = {p: [math.inf, -math.inf, math.inf, 0.0] for p in panels}  # min, max, smallest |v| > 0, count
    total = np.zeros(4, dtype=np.int64)
    counts: dict[str, int] = {}
    for sl in _slabs(view):
        data, _ = _read(view, {dim0: sl}, qs, marked)
        total += np.bincount(_categories(data["stable"], data["status"]).ravel(), minlength=4)
        for meaning, k in _counts(data["stable"], data["status"])[2].items():
            counts[meaning] = counts.get(meaning, 0) + k
        for p in panels:
            fin = values(data, p, sl)
            fin = fin[np.isfinite(fin)]
            if fin.size:
                r, nz = rng[p], np.abs(fin[fin != 0])
                r[0], r[1] = min(r[0], float(fin.min())), max(r[1], float(fin.max()))
                r[2] = min(r[2], float(nz.min())) if nz.size else r[2]
                r[3] += fin.size
    edges = {p: hist_edges(r[0], r[1], r[2], int(r[3]), scale_log(ds, p) if p not in qs else None)
             for p, r in rng.items()}
    hist = {p: np.zeros((4, edges[p][0].size - 1), dtype=np.int64) for p in panels}
    for sl in _slabs(view):
        data, _ = _read(view, {dim0: sl}, qs, marked)
        cat = _categories(data["stable"], data["status"]).ravel()
        for p in panels:
            v = values(data, p, sl)
            for c in range(4):
                hist[p][c] += np.histogram(v[(cat == c) & np.isfinite(v)], bins=edges[p][0])[0]
    stable, unstable, _, missing = (int(t) for t in total)
    decided, what = stable + unstable, "samples" if view.sampled else "points"
    title = [(f"{100 * unstable / decided:.1f} % unstable ({unstable} of the {decided} {what} with a verdict)"
              if decided else f"no {what[:-1]} with a verdict") + (";" if missing else ""),
             *([f"{missing} not computed yet"] if missing else [])]
    fig = _hist_figure(ds, panels, edges, hist, title)
    return Drawn(fig, int(total.sum()), stable, unstable, counts, missing)


# ---------------------------------------------------------------- figures
def scale_log(ds: xr.Dataset, name: str) -> bool:
    """Whether the coordinate ``name`` was swept (or sampled) on a logarithmic scale."""
    return ds[name].attrs.get("scale") == "log"


def label(ds: xr.Dataset, name: str) -> str:
    """Axis label with symbol and unit of a parameter or a quantity."""
    from ..labels import QUANTITIES, axis_label

    if name in ds.data_vars:
        key = _QUANTITY_LABEL.get(name, name)
        if key in QUANTITIES:
            return axis_label(key)
        u = str(ds[name].attrs.get("units", ""))
        return axis_label(name, "" if u == "1" else u)
    return axis_label(name, str(ds[name].attrs.get("units", "")))


def _legend(ax: Axes, handles: list[Any]) -> None:
    """The legend of every figure of the package: above the axes, never over the data."""
    ax.legend(handles=handles, loc="lower left", bbox_to_anchor=(0.0, 1.02), ncols=2, frameon=False,
              borderaxespad=0.0, handlelength=1.5)


def _patch(cat: int) -> Any:
    from matplotlib.patches import Patch

    if cat == 2:
        return Patch(facecolor="white", edgecolor="0.3", hatch="xxx", label=LABELS[2])
    return Patch(facecolor=_FACE[cat], label=LABELS[cat])


@styled
def _map_figure(ds: xr.Dataset, xaxis: tuple[str, np.ndarray], yaxis: tuple[str, np.ndarray], stable: np.ndarray,
              status: np.ndarray, missing: np.ndarray, title: list[str], color: str, field: np.ndarray | None,
              quantity: str) -> Figure:
    """``map --plot``'s figure of the arrays (:func:`~brakesqueal.plotting.plot_map_arrays`), with the points not
    computed yet grey, apart from the points without a verdict and from the grid's stability boundary."""
    from ..plotting import plot_map_arrays

    (xn, xs), (yn, ys) = xaxis, yaxis
    axes = [(n, v, str(ds[n].attrs.get("units", "")), scale_log(ds, n)) for n, v in ((xn, xs), (yn, ys))]
    fig = plot_map_arrays(axes[0], axes[1], stable, status, title="", color=color, field=field)
    _suptitle(fig, title)
    ax = fig.axes[0]
    if field is not None:
        mesh = ax.collections[0]
        if mesh.colorbar is not None:
            mesh.colorbar.set_label(label(ds, quantity))
    if np.any(missing):
        _not_computed_on_map(ax, xs, ys, stable, status, missing)
    return fig


def _not_computed_on_map(ax: Axes, xs: np.ndarray, ys: np.ndarray, stable: np.ndarray, status: np.ndarray,
                         missing: np.ndarray) -> None:
    """Points not computed yet: grey cells (not hatched as points without a verdict), and the grid's stability
    boundary drawn only between computed points (never along the edge of the part not computed)."""
    from matplotlib.colors import ListedColormap
    from matplotlib.contour import ContourSet

    for c in list(ax.collections):
        if isinstance(c, ContourSet):  # the hatching of status >= 2 and the grid boundary: redrawn below
            c.remove()
    failed = (status >= 2) & ~missing
    if np.any(failed):
        ax.contourf(xs, ys, failed.astype(float), levels=[0.5, 1.5], colors="none", hatches=["xxx"])
    z = np.where(status >= 2, np.nan, stable.astype(float))
    boundary = bool(np.any(np.isfinite(z)) and 0 < np.nanmean(z) < 1)
    if boundary and min(z.shape) >= 2:
        zc = np.ma.masked_array(np.nan_to_num(z, nan=0.0), mask=missing)
        ax.contour(xs, ys, zc, levels=[0.5], colors="k", linewidths=1.2)
    grey = np.ma.masked_array(np.ones(missing.shape), mask=~missing)
    ax.pcolormesh(xs, ys, grey, cmap=ListedColormap([NOT_COMPUTED]), vmin=0, vmax=1, shading="nearest",
                  rasterized=True)
    old = ax.get_legend()
    handles = []
    if old is not None:
        for h, t in zip(old.legend_handles, old.get_texts()):
            label = t.get_text()
            if (label == LABELS[2] and not np.any(failed)) or (label.startswith("stability boundary") and
                                                                 not boundary):
                continue
            if h is not None:
                h.set_label(label)
                handles.append(h)
    _legend(ax, [*handles, _patch(3)])


def _cell_edges(xs: np.ndarray, log: bool) -> np.ndarray:
    """Edges of the cells around grid points (midpoints; geometric on a log axis)."""
    if xs.size == 1:
        return np.array([xs[0] / 1.1, xs[0] * 1.1]) if log and xs[0] > 0 else np.array([xs[0] - 0.5, xs[0] + 0.5])
    mid = np.sqrt(xs[1:] * xs[:-1]) if log else 0.5 * (xs[1:] + xs[:-1])
    first = xs[0] ** 2 / mid[0] if log else 2 * xs[0] - mid[0]
    last = xs[-1] ** 2 / mid[-1] if log else 2 * xs[-1] - mid[-1]
    return np.concatenate([[first], mid, [last]])


def _runs(cat: np.ndarray) -> list[tuple[int, int, int]]:
    """``(category, first, last + 1)`` of every run of equal categories."""
    cut = np.flatnonzero(np.diff(cat)) + 1
    starts = [0, *cut.tolist()]
    ends = [*cut.tolist(), cat.size]
    return [(int(cat[a]), a, b) for a, b in zip(starts, ends)]


@styled
def _slice_figure(ds: xr.Dataset, xn: str, xs: np.ndarray, cat: np.ndarray, values: np.ndarray | None,
                  q: str | None, title: list[str]) -> Figure:
    """A quantity along one axis, the stretches of each verdict shaded (the map's colours)."""
    from ..plotting import new_figure

    fig, ax = new_figure()
    log = scale_log(ds, xn) and bool(np.all(xs > 0))
    edges = _cell_edges(xs, log)
    for c, a, b in _runs(cat):
        style: dict[str, Any] = ({"facecolor": "white", "edgecolor": "0.3", "hatch": "xxx"} if c == 2 else
                                 {"facecolor": _FACE[c]})
        ax.axvspan(edges[a], edges[b], lw=0, zorder=0, gid=f"verdict-{c}", **style)
    if values is not None and q is not None:
        ax.plot(xs, values, "k-", lw=1, marker="." if xs.size <= 60 else None, ms=3, zorder=3)
        fin = values[np.isfinite(values)]
        if q in ("max_real", "margin"):
            ax.axhline(0.0, color="0.5", lw=0.8, zorder=2)
        if fin.size:
            big, small = float(np.max(np.abs(fin))), float(np.min(np.abs(fin[fin != 0]))) if np.any(fin) else 0.0
            if np.all(fin > 0) and big > 1e3 * small:
                ax.set_yscale("log")
            elif small > 0 and big > 1e3 * small:
                ax.set_yscale("symlog", linthresh=max(big * 1e-4, small))
        ax.set_ylabel(label(ds, q))
    else:
        ax.set_yticks([])
    if log:
        ax.set_xscale("log")
    if xs.size > 1:
        ax.set_xlim(xs[0], xs[-1])
    ax.set_xlabel(label(ds, xn))
    _legend(ax, [_patch(c) for c in range(4) if np.any(cat == c)])
    _suptitle(fig, title)
    return fig


@styled
def _samples_figure(ds: xr.Dataset, xaxis: tuple[str, np.ndarray], yaxis: tuple[str, np.ndarray], cat: np.ndarray,
                    values: np.ndarray | None, quantity: str, title: list[str]) -> Figure:
    """The samples over two sampled parameters: coloured by verdict (the map's colours) or by a quantity."""
    from ..plotting import new_figure

    fig, ax = new_figure()
    (xn, xs), (yn, ys) = xaxis, yaxis
    size = float(np.clip(2e3 / max(xs.size, 1), 1.0, 16.0))
    if values is None:
        for c in (3, 2, 0, 1):
            m = cat == c
            if np.any(m):
                face = ("white" if c == 2 else _FACE[c])
                edge = ("#2e7d32", "#c62828", "0.3", "0.6")[c]
                ax.scatter(xs[m], ys[m], s=size, c=face, edgecolors=edge, linewidths=0.4, gid=f"verdict-{c}")
        _legend(ax, [_patch(c) for c in range(4) if np.any(cat == c)])
    else:
        fin = np.isfinite(values)
        pts = ax.scatter(xs[fin], ys[fin], s=size, c=values[fin], cmap="viridis", linewidths=0)
        if np.any(~fin):
            ax.scatter(xs[~fin], ys[~fin], s=size, c=NOT_COMPUTED, linewidths=0, label="no value")
        fig.colorbar(pts, ax=ax, label=label(ds, quantity))
    for name, setter in ((xn, ax.set_xscale), (yn, ax.set_yscale)):
        if scale_log(ds, name):
            setter("log")
    ax.set_xlabel(label(ds, xn))
    ax.set_ylabel(label(ds, yn))
    _suptitle(fig, title)
    return fig


def hist_edges(lo: float, hi: float, small: float, n: int, log: bool | None) -> tuple[np.ndarray, str]:
    """Bin edges over ``[lo, hi]`` and the axis scale: logarithmic for positive values over more than three
    decades (or a log-sampled parameter), symmetric-logarithmic for signed ones, else linear."""
    bins = int(np.clip(math.ceil(math.sqrt(max(n, 1))), 5, 40))
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return np.array([0.0, 1.0]), "linear"
    if hi <= lo:
        w = 0.5 * abs(lo) if lo else 0.5
        return np.array([lo - w, hi + w]), "linear"
    big = max(abs(lo), abs(hi))
    if (log is True or (log is None and lo > 0 and hi > 1e3 * lo)) and lo > 0:
        e = np.geomspace(lo, hi, bins + 1)
        e[0], e[-1] = lo, hi
        return e, "log"
    if log is None and small > 0 and big > 1e3 * small and lo < 0:
        t = max(big * 1e-4, small)

        def fwd(v: float) -> float:
            return math.copysign(math.log10(1 + abs(v) / t), v)

        u = _zero_edge(fwd(lo), fwd(hi), bins)
        return np.sign(u) * t * (10 ** np.abs(u) - 1), f"symlog:{t!r}"
    return _zero_edge(lo, hi, bins), "linear"


def _zero_edge(lo: float, hi: float, bins: int) -> np.ndarray:
    """About ``bins`` equal bins over ``[lo, hi]``; one edge at 0 when the range has both signs (the verdict's
    boundary of ``max_real`` and ``margin``)."""
    if not lo < 0 < hi:
        e = np.linspace(lo, hi, bins + 1)
        e[0], e[-1] = lo, hi
        return e
    w = (hi - lo) / bins
    return w * np.arange(math.floor(lo / w), math.ceil(hi / w) + 1)


@styled
def _hist_figure(ds: xr.Dataset, panels: list[str], edges: dict[str, tuple[np.ndarray, str]],
                 hist: dict[str, np.ndarray], title: list[str]) -> Figure:
    """One panel per quantity or parameter, the counts of each bin stacked by verdict (the map's colours)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    n = len(panels)
    fig = Figure(figsize=(3.5, 0.8 + 1.5 * n), layout="constrained")
    FigureCanvasAgg(fig)
    axs = fig.subplots(n, 1, squeeze=False)[:, 0]
    shown = set()
    for ax, p in zip(axs, panels):
        e, scale = edges[p]
        bottom = np.zeros(e.size - 1)
        for c in range(4):
            h = hist[p][c]
            if not np.any(h):
                continue
            shown.add(c)
            ax.bar(e[:-1], h, width=np.diff(e), bottom=bottom, align="edge", lw=0.3, edgecolor="0.4",
                   color=("white" if c == 2 else _FACE[c]),
                   hatch="xxx" if c == 2 else None, gid=f"verdict-{c}")
            bottom = bottom + h
        if scale == "log":
            ax.set_xscale("log")
        elif scale.startswith("symlog:"):
            ax.set_xscale("symlog", linthresh=float(scale.split(":", 1)[1]))
        ax.set_xlim(e[0], e[-1])
        ax.set_xlabel(label(ds, p))
        ax.set_ylabel(("samples" if ds["stable"].dims == ("sample",) else "points") + " [per bin]")
    _legend(axs[0], [_patch(c) for c in range(4) if c in shown])
    _suptitle(fig, title)
    return fig
