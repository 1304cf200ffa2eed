"""Matplotlib figures of the stability analysis (Agg backend; figures are returned, never shown)."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, ParamSpec, TypeVar, overload

import numpy as np

if TYPE_CHECKING:
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure, SubFigure

    from .analysis.modes import ModeTracks
    from .results import CrossingResult, StabilityMap

__all__ = ["new_figure", "styled", "plot_map", "plot_map_arrays", "map_title", "MAP_COLORS", "MAP_STABLE",
           "MAP_PAD_ONLY", "MAP_UNSTABLE", "plot_path", "plot_critical_curves", "save"]

_P = ParamSpec("_P")
_R = TypeVar("_R")


@overload
def new_figure(ax: None = None, size: tuple[float, float] = ...) -> tuple[Figure, Axes]: ...
@overload
def new_figure(ax: Axes, size: tuple[float, float] = ...) -> tuple[Figure | SubFigure, Axes]: ...


def new_figure(ax: Axes | None = None, size: tuple[float, float] = (3.5, 2.6)) -> tuple[Figure | SubFigure, Axes]:
    """A new ``(figure, axes)`` pair on the Agg canvas (single journal column by default), or the figure of ``ax``
    (a :class:`~matplotlib.figure.SubFigure` for the axes of a sub-figure)."""
    if ax is not None:
        return ax.figure, ax
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig, fig.add_subplot()


def styled(func: Callable[_P, _R]) -> Callable[_P, _R]:
    """Draw inside the one figure style of the package (:data:`brakesqueal.labels.STYLE`)."""
    import functools

    @functools.wraps(func)
    def wrapper(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        import matplotlib

        from .labels import STYLE

        with matplotlib.rc_context(STYLE):
            return func(*args, **kwargs)

    return wrapper


def _label(name: str, units: str) -> str:
    from .labels import axis_label

    return axis_label(name, units)


#: Colourings of a map: the certified verdict, or a continuous field with the verdict's boundary on top.
MAP_COLORS = ("verdict", "max_real", "frequency")
#: Fill colour of the stable points of a verdict map (the explorer's map uses the same).
MAP_STABLE = "#c8e6c9"
#: Fill colour of the unstable (squealing) points of a verdict map (the explorer's map uses the same).
MAP_UNSTABLE = "#f4c7c3"
#: The explorer's fill of points whose disk modes are stable while a massless pad's own 0 Hz mode is unstable
#: (figures hatch them over :data:`MAP_STABLE`).
MAP_PAD_ONLY = "#e6ee9c"


@overload
def plot_map(m: StabilityMap, ax: None = None, *, x: str | None = None, title: str | None = None,
             color: str = "verdict") -> Figure: ...
@overload
def plot_map(m: StabilityMap, ax: Axes, *, x: str | None = None, title: str | None = None,
             color: str = "verdict") -> Figure | SubFigure: ...


def plot_map(m: StabilityMap, ax: Axes | None = None, *, x: str | None = None, title: str | None = None,
             color: str = "verdict") -> Figure | SubFigure:
    """Plot a :class:`~brakesqueal.results.StabilityMap`: stable region, boundary, failed points.

    Parameters
    ----------
    m : StabilityMap
        The map.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into.
    x : str, optional
        The horizontal axis (default the inner dimension).
    title : str, optional
        Axes title.
    color : {"verdict", "max_real", "frequency"}
        What the colours show (see :func:`plot_map_arrays`).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from .results import boundary_of

    outer, inner = m.dims
    ds = m.data
    xn = x or inner
    yn = outer if xn == inner else inner
    axes = [(n, ds[n].values, ds[n].attrs.get("units", ""), ds[n].attrs.get("scale") == "log") for n in (xn, yn)]
    field = ds[color].transpose(yn, xn).values if color in ("max_real", "frequency") and color in ds else None
    disk = ds["disk_stable"].transpose(yn, xn).values if "disk_stable" in ds else None
    return plot_map_arrays(axes[0], axes[1], ds["stable"].transpose(yn, xn).values,
                           ds["status"].transpose(yn, xn).values, ax=ax,
                           title=title if title is not None else map_title(ds.attrs.get("space", ""), xn, yn),
                           boundary=boundary_of(ds, (xn, yn)), color=color, field=field, disk_stable=disk)


def _title(fig: Figure | SubFigure, ax: Axes, title: str, own: bool) -> None:
    """A figure of its own gets a centred title above the legend; axes in a user's figure get an axes title."""
    if not title:
        return
    if own:
        fig.suptitle(title, fontsize="medium")
    else:
        ax.set_title(title, loc="right", fontsize="medium", pad=28)


def map_title(space: str, xn: str, yn: str) -> str:
    """Default title of a map: what it shows, over which parameters, for which preset."""
    from .labels import symbol

    return f"${symbol(yn)}$ vs ${symbol(xn)}$ ({space})"


@overload
def plot_map_arrays(xaxis: tuple[str, np.ndarray, str, bool], yaxis: tuple[str, np.ndarray, str, bool],
                    stable: np.ndarray, status: np.ndarray, *, ax: None = None, title: str = "",
                    boundary: tuple[np.ndarray, np.ndarray] | None = None, color: str = "verdict",
                    field: np.ndarray | None = None, disk_stable: np.ndarray | None = None) -> Figure: ...
@overload
def plot_map_arrays(xaxis: tuple[str, np.ndarray, str, bool], yaxis: tuple[str, np.ndarray, str, bool],
                    stable: np.ndarray, status: np.ndarray, *, ax: Axes, title: str = "",
                    boundary: tuple[np.ndarray, np.ndarray] | None = None, color: str = "verdict",
                    field: np.ndarray | None = None, disk_stable: np.ndarray | None = None
                    ) -> Figure | SubFigure: ...


@styled
def plot_map_arrays(xaxis: tuple[str, np.ndarray, str, bool], yaxis: tuple[str, np.ndarray, str, bool],
                    stable: np.ndarray, status: np.ndarray, *, ax: Axes | None = None, title: str = "",
                    boundary: tuple[np.ndarray, np.ndarray] | None = None, color: str = "verdict",
                    field: np.ndarray | None = None, disk_stable: np.ndarray | None = None
                    ) -> Figure | SubFigure:
    """Plot a stability map given as arrays (what :func:`plot_map` draws, without xarray).

    Where a massless pad's own (0 Hz, non-oscillatory) mode is the only unstable one (``stable`` false,
    ``disk_stable`` 1), the verdict colouring shows the disk's modes: those points are drawn stable and
    hatched, with their own legend entry, and the boundary drawn is the disk modes' (on the grid).

    Parameters
    ----------
    xaxis, yaxis : tuple
        ``(name, values, units, log)`` of the horizontal and vertical axes.
    stable, status : ndarray, shape (len(y values), len(x values))
        Certified verdicts and :class:`~brakesqueal.status.PointStatus` codes.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into (default: a new figure).
    title : str
        Axes title.
    boundary : tuple of ndarray, optional
        The refined stability boundary ``(x values, y values)``, curves
        separated by NaN (:func:`~brakesqueal.analysis.boundary.stability_boundary`);
        without it the boundary is the grid contour of ``stable``.
    color : {"verdict", "max_real", "frequency"}
        ``verdict`` shades stable and unstable points; ``max_real`` and
        ``frequency`` colour the points by that field (``field``) with a colour bar.
    field : ndarray, optional
        The field for ``color = "max_real"`` or ``"frequency"``.
    disk_stable : ndarray of int, optional
        The verdict of the disk's modes alone (1 stable, 0 unstable, -1 none; the map's ``disk_stable``).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ParameterError
        An unknown ``color``, or a field colouring without the field (a verdict-only map).
    """
    from matplotlib.colors import ListedColormap, SymLogNorm
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    from .errors import ParameterError

    if color not in MAP_COLORS:
        raise ParameterError(f"color must be one of {', '.join(MAP_COLORS)}; got {color!r}")
    if color != "verdict" and field is None:
        raise ParameterError(f"color = {color!r} needs the map's {color} (a map computed without --no-eigen)")
    own = ax is None
    fig, ax = new_figure(ax)
    (xn, xs, xu, xlog), (yn, ys, yu, ylog) = xaxis, yaxis
    status = np.asarray(status)
    failed = status >= 2
    z = np.where(failed, np.nan, np.asarray(stable, dtype=float))
    handles: list[Artist] = []
    pad_only = np.zeros(z.shape, dtype=bool)
    if disk_stable is not None:
        disk = np.asarray(disk_stable)
        pad_only = ~failed & (z == 0) & (disk == 1)
    if pad_only.any() and disk_stable is not None:  # colour the disk's modes; the pad-only points marked
        failed = failed | (np.asarray(disk_stable) < 0)
        z = np.where(failed, np.nan, (np.asarray(disk_stable) == 1).astype(float))
        boundary = None  # the stored boundary is that of every mode: the disk's drawn on the grid below
    if color == "verdict":
        ax.pcolormesh(xs, ys, z, cmap=ListedColormap([MAP_UNSTABLE, MAP_STABLE]), vmin=0, vmax=1, shading="nearest",
                      rasterized=True)
        handles += [Patch(facecolor=MAP_STABLE, label="stable"),
                    Patch(facecolor=MAP_UNSTABLE, label="unstable (squeal)")]
        if pad_only.any():
            import matplotlib as mpl

            with mpl.rc_context({"hatch.color": "0.45", "hatch.linewidth": 0.5}):
                ax.contourf(xs, ys, pad_only.astype(float), levels=[0.5, 1.5], colors="none", hatches=["///"])
            handles.append(Patch(facecolor=MAP_STABLE, edgecolor="0.45", hatch="///", lw=0.5,
                                 label="pad's own 0 Hz mode only"))
    else:
        from .labels import axis_label

        f = np.where(failed, np.nan, np.asarray(field, dtype=float))
        if color == "max_real":
            lim = float(np.nanmax(np.abs(f))) if np.any(np.isfinite(f)) else 1.0
            thresh = max(lim * 1e-4, 1e-12)
            norm = SymLogNorm(linthresh=thresh, vmin=-lim, vmax=lim)
            mesh = ax.pcolormesh(xs, ys, f, cmap="RdBu_r", norm=norm, shading="nearest", rasterized=True)
            top = np.floor(np.log10(lim))
            dec = 10.0 ** np.arange(top, np.log10(thresh) + 0.5, -2.0)  # every other decade, none near 0
            ticks = [*(-dec), 0.0, *dec[::-1]]
        else:
            mesh = ax.pcolormesh(xs, ys, f, cmap="viridis", shading="nearest", rasterized=True)
            ticks = None
        fig.colorbar(mesh, ax=ax, label=axis_label(color), ticks=ticks)
    if np.any(failed):
        ax.contourf(xs, ys, failed.astype(float), levels=[0.5, 1.5], colors="none", hatches=["xxx"])
        handles.append(Patch(facecolor="white", edgecolor="0.3", hatch="xxx", label="no verdict (see status)"))
    if boundary is not None and np.any(np.isfinite(boundary[0])):
        ax.plot(boundary[0], boundary[1], "k-", lw=1.2)
        handles.append(Line2D([], [], color="k", lw=1.2, label="stability boundary"))
    elif np.any(np.isfinite(z)) and 0 < np.nanmean(z) < 1:  # all-NaN (no verdict anywhere): no boundary
        ax.contour(xs, ys, np.nan_to_num(z, nan=0.0), levels=[0.5], colors="k", linewidths=1.2)
        what = "disk modes' boundary (grid)" if pad_only.any() else "stability boundary (grid)"
        handles.append(Line2D([], [], color="k", lw=1.2, label=what))
    if xlog:
        ax.set_xscale("log")
    if ylog:
        ax.set_yscale("log")
    ax.set_xlim(xs[0], xs[-1])
    ax.set_ylim(ys[0], ys[-1])
    ax.set_xlabel(_label(xn, xu))
    ax.set_ylabel(_label(yn, yu))
    # outside the axes, above them: never over the data (loc="best" would also test every mesh cell)
    ax.legend(handles=handles, loc="lower left", bbox_to_anchor=(0.0, 1.02), ncols=2, frameon=False,
              borderaxespad=0.0, handlelength=1.5)
    _title(fig, ax, title, own)
    return fig


@overload
def plot_path(r: CrossingResult, ax: None = None) -> Figure: ...
@overload
def plot_path(r: CrossingResult, ax: Axes) -> Figure | SubFigure: ...


@styled
def plot_path(r: CrossingResult, ax: Axes | None = None) -> Figure | SubFigure:
    """Largest real part along a 1-D path (the result's stored ``profile``) with its crossings marked.

    Parameters
    ----------
    r : CrossingResult
        A result of :func:`~brakesqueal.analysis.crossings.crossings` or
        :func:`~brakesqueal.analysis.crossings.critical_speeds`.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = new_figure(ax)
    if r.profile is not None:
        grid, vals = r.profile
        ax.plot(grid, vals, "k-", lw=1)
    ax.axhline(0, color="0.5", lw=0.8)
    for v, d in r.crossings:
        ax.axvline(v, color="tab:red" if d == "destabilizing" else "tab:green", ls="--", lw=1)
    for a, b in r.undecided_ranges:
        ax.axvspan(a, b, color="0.85", lw=0)
    if r.log:
        ax.set_xscale("log")
    ax.set_yscale("symlog", linthresh=1e-2)
    from .labels import axis_label, unit

    ax.set_xlabel(axis_label(r.parameter, unit(r.parameter, getattr(r, "space", None))))
    ax.set_ylabel(axis_label("max_real"))
    from matplotlib.lines import Line2D

    ax.legend(handles=[Line2D([], [], color="tab:red", ls="--", label="destabilizing"),
                       Line2D([], [], color="tab:green", ls="--", label="stabilizing")],
              loc="lower left", bbox_to_anchor=(0.0, 1.02), ncols=2, frameon=False, borderaxespad=0.0)
    return fig


@overload
def plot_critical_curves(diff: np.ndarray, curves: dict[str, np.ndarray], ax: None = None,
                         restab: dict[str, np.ndarray] | None = None,
                         tips: dict[str, list[tuple[float, float]]] | None = None, title: str = "") -> Figure: ...
@overload
def plot_critical_curves(diff: np.ndarray, curves: dict[str, np.ndarray], ax: Axes,
                         restab: dict[str, np.ndarray] | None = None,
                         tips: dict[str, list[tuple[float, float]]] | None = None,
                         title: str = "") -> Figure | SubFigure: ...


@styled
def plot_critical_curves(diff: np.ndarray, curves: dict[str, np.ndarray], ax: Axes | None = None,
                         restab: dict[str, np.ndarray] | None = None,
                         tips: dict[str, list[tuple[float, float]]] | None = None,
                         title: str = "") -> Figure | SubFigure:
    """Ω_crit versus μ1 − μ2 for several k_ip (paper Fig. 3), optionally as closed squeal regions.

    Parameters
    ----------
    diff : ndarray
        The grid of ``mu1 - mu2``.
    curves : dict of str to ndarray
        Onset speeds per ``k_ip`` label (NaN: stable throughout).
    ax : matplotlib.axes.Axes, optional
        Axes to draw into.
    restab : dict of str to ndarray, optional
        Re-stabilisation speeds per label: with them each curve is drawn as the
        closed boundary of the unstable region (onset below, re-stabilisation
        above, joined at the tips), on a log axis.
    tips : dict of str to list of (float, float), optional
        Where onset and re-stabilisation meet (:func:`brakesqueal.reproduce.fig3_tips`):
        the curves end there instead of at the last grid point.
    title : str
        Axes title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from .labels import axis_label, symbol

    own = ax is None
    fig, ax = new_figure(ax)
    for label, y in curves.items():
        fin = np.flatnonzero(np.isfinite(y))
        if fin.size == 0:
            continue
        i0, i1 = fin[0], fin[-1]
        tl = [t for t in (tips or {}).get(label, []) if t[0] < diff[i0]]
        tr = [t for t in (tips or {}).get(label, []) if t[0] > diff[i1]]
        xs = [*([tl[-1][0]] if tl else []), *diff[i0:i1 + 1], *([tr[0][0]] if tr else [])]
        lo = [*([tl[-1][1]] if tl else []), *y[i0:i1 + 1], *([tr[0][1]] if tr else [])]
        name = "∞" if label == "inf" else label
        if restab is not None and label in restab and np.all(np.isfinite(restab[label][i0:i1 + 1])):
            up = restab[label][i0:i1 + 1]
            px = np.array([*xs, *diff[i0:i1 + 1][::-1], xs[0]])
            py = np.array([*lo, *up[::-1], lo[0]])
            if not tl:  # no tip on this side: leave the region open there
                px, py = px[:-1], py[:-1]
            line, = ax.plot(px, py, "-", label=f"${symbol('k_ip')}$ = {name} N/m")
            ax.fill(px, py, color=line.get_color(), alpha=0.08, lw=0)
        else:
            ax.plot(xs, lo, "-", label=f"${symbol('k_ip')}$ = {name} N/m")
    if restab is not None:
        ax.set_yscale("log")
        ax.set_ylabel(axis_label("Omega", "rad/s") + " (shaded: squeal)")
    else:
        ax.set_ylabel(axis_label("Omega_crit"))
    ax.set_xlabel(f"${symbol('mu1')} - {symbol('mu2')}$  (${symbol('mu1')} + {symbol('mu2')} = 1$)")
    from matplotlib.ticker import MultipleLocator

    # fixed ticks: with the automatic locator the tick set (and with it the constrained layout's margins) can
    # change from one draw to the next, and the last tick label then overhangs the figure's edge
    ax.xaxis.set_major_locator(MultipleLocator(0.25))
    ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.02), ncols=2, frameon=False, borderaxespad=0.0)
    _title(fig, ax, title, own)
    return fig


def save(fig: Figure, path: str, dpi: int = 300) -> str:
    """Save a figure (format from the suffix: PNG, SVG, PDF) atomically and return the path.

    Written through :func:`brakesqueal.outputs.write_with`: a failure (a full
    disk, in any format's writer) is one :class:`~brakesqueal.errors.OutputError`
    line and leaves an existing file of that name as it was.
    """
    from .outputs import write_with

    write_with(path, lambda tmp: fig.savefig(tmp, dpi=dpi), what="figure")
    return path


#: Modes drawn in colour with a legend in a mode-coupling diagram (a larger model: its least stable ones).
MODES_LABELLED = 8


@styled
def plot_modes(tracks: ModeTracks, fig: Figure | None = None) -> Figure:
    """Mode-coupling diagram of :class:`~brakesqueal.analysis.modes.ModeTracks`: frequency and Re λ vs the parameter.

    Coalescences are marked with circles on the frequency panel, stability
    crossings with vertical dashed lines (red: destabilizing, green:
    stabilizing).  A model with more than :data:`MODES_LABELLED` modes shows its least stable modes (those that
    become unstable, else the three of largest real part) in colour and the others in grey.  Returns the figure.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    if fig is None:
        fig = Figure(figsize=(3.5, 4.0), layout="constrained")
        FigureCanvasAgg(fig)
    ax_f, ax_r = fig.subplots(2, 1, sharex=True)
    x = tracks.values
    f, re = tracks.frequencies, tracks.eigenvalues.real
    many = f.shape[1] > MODES_LABELLED
    with np.errstate(invalid="ignore"):
        peak = np.nanmax(np.where(np.isfinite(re), re, -np.inf), axis=0)
    order = np.argsort(-peak)
    shown = set(order[:MODES_LABELLED].tolist()) if not many else set(
        [int(k) for k in order if peak[k] > 0][:MODES_LABELLED] or order[:3].tolist())
    for k in range(f.shape[1]):
        if k not in shown:  # a large model: every other mode in grey, unlabelled
            ax_f.plot(x, f[:, k], lw=0.6, color="0.75", zorder=1)
            ax_r.plot(x, re[:, k], lw=0.6, color="0.75", zorder=1)
    for k in sorted(shown):
        line, = ax_f.plot(x, f[:, k], lw=1.3, label=f"mode {k}", zorder=3)
        ax_r.plot(x, re[:, k], lw=1.3, color=line.get_color(), zorder=3)
    for c in tracks.coalescences:
        if not many or set(c["modes"]) & shown:
            ax_f.plot([c["value"]], [c["frequency_hz"]], "o", mfc="none", mec="k", ms=7, zorder=4)
    for c in tracks.crossings:
        color = "tab:red" if c["direction"] == "destabilizing" else "tab:green"
        for ax in (ax_f, ax_r):
            ax.axvline(c["value"], color=color, ls="--", lw=0.8)
    ax_r.axhline(0.0, color="0.4", lw=0.8)
    if tracks.log:
        ax_r.set_xscale("log")
    from .labels import axis_label

    ax_r.set_xlabel(axis_label(tracks.parameter, tracks.units or ""))
    ax_f.set_ylabel(axis_label("frequency"))
    ax_r.set_ylabel(r"Re $\lambda$ [1/s]")
    if many:  # the labelled modes' real parts, near zero, where squeal starts
        sel = re[:, sorted(shown)]
        span = float(np.nanmax(np.abs(sel))) if np.isfinite(sel).any() else 1.0
        ax_r.set_ylim(-3 * span, 3 * span)
        ax_r.ticklabel_format(axis="y", style="sci", scilimits=(-2, 3))
    else:
        ax_r.set_yscale("symlog", linthresh=max(1e-3, float(np.nanmax(np.abs(re))) * 1e-3))
    ax_f.legend(loc="lower left", bbox_to_anchor=(0.0, 1.02), ncols=3, frameon=False, borderaxespad=0.0,
                fontsize="small")
    title = f"mode coupling ({tracks.model})" + (f"\nthe least stable {len(shown)} of {f.shape[1]} modes in colour"
                                                 if many else "")
    fig.suptitle(title, fontsize="medium")
    return fig

