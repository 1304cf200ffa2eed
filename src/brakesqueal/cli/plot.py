"""``brakesqueal plot STORE.zarr``: a figure of a sweep's results (map, slice or histograms).

Registered by :mod:`brakesqueal.cli` through :func:`register`; xarray, zarr and
matplotlib are imported inside the command.  The figure is drawn by
:mod:`brakesqueal.sweep.plots`; the store and the options are checked before
anything is read, the output path before anything is drawn, and the figure is
written atomically by :func:`brakesqueal.plotting.save`.
"""

from __future__ import annotations

import sys
from enum import Enum
from typing import Annotated, Optional

import typer

from ._options import PLOT_SUFFIXES

__all__ = ["register"]


class _Kind(str, Enum):
    map = "map"
    slice = "slice"
    hist = "hist"


def plot(
    store: Annotated[str, typer.Argument(help="Zarr store written by brakesqueal sweep.")],
    out: Annotated[Optional[str], typer.Option(
        "--out", help="Figure to write: PNG, SVG or PDF (default: the store's name with .png, beside it).")] = None,
    kind: Annotated[Optional[_Kind], typer.Option(
        "--kind", help="map: stability map over two axes (default with two or more axes); slice: along one axis "
                       "(default with one); hist: histograms, stacked by verdict (default for sampled "
                       "studies).")] = None,
    x: Annotated[Optional[str], typer.Option(
        "--x", help="Horizontal axis (default: map: the later of the two longest axes; slice: the longest); "
                    "hist of a sampled study: a sampled parameter.")] = None,
    y: Annotated[Optional[str], typer.Option("--y", help="Vertical axis of a map (default: the other longest "
                                                         "axis).")] = None,
    color: Annotated[str, typer.Option(
        "--color", help="What is shown: verdict (default), or a quantity the study computed: max_real, frequency, "
                        "margin, critical_speed.")] = "verdict",
    at: Annotated[Optional[list[str]], typer.Option(
        "--at", help="NAME=VALUE: draw the grid value of axis NAME nearest to VALUE (repeatable; an axis not "
                     "given is drawn at its first value).")] = None,
) -> None:
    """Figure of a sweep's results: stability map, slice along one axis or histograms, chosen from the store's
    dimensions; points of chunks not computed yet are drawn grey."""
    from ..outputs import check_output
    from ..plotting import save
    from ..sweep.plots import default_figure_path, parse_at, plot_view, sweep_view
    from ._options import note

    view = sweep_view(store, kind=kind.value if kind is not None else None, x=x, y=y, color=color,
                      at=parse_at(at or []))
    target = out if out is not None else str(default_figure_path(store))
    check_output(target, what="--out", suffixes=PLOT_SUFFIXES)
    result = plot_view(view)
    for line in result.notes:
        note(line)
    save(result.figure, target)  # written atomically (brakesqueal.outputs.write_with)
    sys.stdout.write(f"wrote {target}: {result.text()}\n")


def register(app: typer.Typer) -> None:
    """Add ``plot`` to ``app``.

    Parameters
    ----------
    app : typer.Typer
        The main application.
    """
    app.command("plot")(plot)
