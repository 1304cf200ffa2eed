"""Matplotlib figures of the stability analysis (Agg backend; figures are returned, never shown)."""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["new_figure", "plot_map", "plot_map_arrays", "plot_path", "plot_critical_curves", "save"]


def new_figure(ax: Any = None, size: tuple[float, float] = (6.4, 4.8)) -> tuple[Any, Any]:
    """A new ``(figure, axes)`` pair on the Agg canvas, or the figure of ``ax``."""
    if ax is not None:
        return ax.figure, ax
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig, fig.add_subplot()


def _label(name: str, units: str) -> str:
    return f"{name} [{units}]" if units else name


def plot_map(m: Any, ax: Any = None, *, x: str | None = None, title: str | None = None) -> Any:
    """Plot a :class:`~brakesqueal.results.StabilityMap`: stable region, boundary, invalid points."""
    outer, inner = m.dims
    ds = m.data
    xn = x or inner
    yn = outer if xn == inner else inner
    axes = [(n, ds[n].values, ds[n].attrs.get("units", ""), ds[n].attrs.get("scale") == "log") for n in (xn, yn)]
    return plot_map_arrays(axes[0], axes[1], ds["stable"].transpose(yn, xn).values,
                           ds["status"].transpose(yn, xn).values, ax=ax,
                           title=title or f"stability map ({ds.attrs.get('space', '')})")


def plot_map_arrays(xaxis: tuple[str, np.ndarray, str, bool], yaxis: tuple[str, np.ndarray, str, bool],
                    stable: np.ndarray, status: np.ndarray, *, ax: Any = None, title: str = "") -> Any:
    """Plot a stability map given as arrays (what :func:`plot_map` draws, without xarray).

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

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    fig, ax = new_figure(ax)
    (xn, xs, xu, xlog), (yn, ys, yu, ylog) = xaxis, yaxis
    status = np.asarray(status)
    z = np.where(status >= 2, np.nan, np.asarray(stable, dtype=float))
    ax.pcolormesh(xs, ys, z, cmap=ListedColormap(["#f4c7c3", "#c8e6c9"]), vmin=0, vmax=1, shading="nearest",
                  rasterized=True)
    if np.any(status >= 2):
        ax.contourf(xs, ys, (status >= 2).astype(float), levels=[0.5, 1.5], colors="none", hatches=["xx"])
    if 0 < np.nanmean(z) < 1:
        ax.contour(xs, ys, np.nan_to_num(z, nan=0.0), levels=[0.5], colors="k", linewidths=1.2)
    if xlog:
        ax.set_xscale("log")
    if ylog:
        ax.set_yscale("log")
    ax.set_xlabel(_label(xn, xu))
    ax.set_ylabel(_label(yn, yu))
    # a fixed place beside the axes: loc="best" tests every cell of the mesh (minutes for 1e6 cells)
    ax.legend(handles=[Patch(color="#c8e6c9", label="stable"), Patch(color="#f4c7c3", label="unstable (squeal)")],
              loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8)
    ax.set_title(title)
    return fig


def plot_path(r: Any, ax: Any = None) -> Any:
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
    ax.set_xlabel(r.parameter)
    ax.set_ylabel("max Re λ [1/s]")
    return fig


def plot_critical_curves(diff: np.ndarray, curves: dict[str, np.ndarray], ax: Any = None,
                         restab: dict[str, np.ndarray] | None = None) -> Any:
    """Ω_crit (and, dotted, the re-stabilising speed) versus μ1 − μ2 for several k_ip."""
    fig, ax = new_figure(ax)
    for i, (label, y) in enumerate(curves.items()):
        line, = ax.plot(diff, y, "-", lw=1.5, label=f"k_ip = {label}")
        if restab is not None and label in restab:
            ax.plot(diff, restab[label], ":", lw=1, color=line.get_color())
    ax.set_xlabel("μ1 − μ2 (μ1 + μ2 = 1)")
    ax.set_ylabel("Ω_crit [rad/s]")
    ax.legend(fontsize=8)
    return fig


def save(fig: Any, path: str, dpi: int = 150) -> str:
    """Save a figure (format from the suffix: PNG, SVG, PDF) and return the path."""
    fig.savefig(path, dpi=dpi)
    return path


def plot_modes(tracks: Any, fig: Any = None) -> Any:
    """Mode-coupling diagram of :class:`~brakesqueal.analysis.modes.ModeTracks`: frequency and Re λ vs the parameter.

    Coalescences are marked with circles on the frequency panel, stability
    crossings with vertical dashed lines (red: destabilizing, green:
    stabilizing).  Returns the figure.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    if fig is None:
        fig = Figure(figsize=(6.4, 5.2), layout="constrained")
        FigureCanvasAgg(fig)
    ax_f, ax_r = fig.subplots(2, 1, sharex=True)
    x = tracks.values
    f, re = tracks.frequencies, tracks.eigenvalues.real
    for k in range(f.shape[1]):
        line, = ax_f.plot(x, f[:, k], lw=1.3, label=f"mode {k}")
        ax_r.plot(x, re[:, k], lw=1.3, color=line.get_color())
    for c in tracks.coalescences:
        ax_f.plot([c["value"]], [c["frequency_hz"]], "o", mfc="none", mec="k", ms=7)
    for c in tracks.crossings:
        color = "tab:red" if c["direction"] == "destabilizing" else "tab:green"
        for ax in (ax_f, ax_r):
            ax.axvline(c["value"], color=color, ls="--", lw=0.8)
    ax_r.axhline(0.0, color="0.4", lw=0.8)
    if tracks.log:
        ax_r.set_xscale("log")
    unit = f" [{tracks.units}]" if tracks.units else ""
    ax_r.set_xlabel(f"{tracks.parameter}{unit}")
    ax_f.set_ylabel("frequency [Hz]")
    ax_r.set_ylabel(r"Re $\lambda$ [1/s]")
    ax_r.set_yscale("symlog", linthresh=max(1e-3, float(np.nanmax(np.abs(re))) * 1e-3))
    ax_f.legend(fontsize=8, loc="best", ncols=2)
    ax_f.set_title(f"mode coupling along {tracks.parameter} ({tracks.model})")
    return fig
