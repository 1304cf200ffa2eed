"""``brakesqueal region``: the squeal region diagram in two parameters (issue 28).

Hopf curves with ``l1`` along them and codimension-2 points
(:func:`brakesqueal.region.region_diagram`), the certified linear stability map,
as text or JSON, ``--out FILE.nc`` (xarray/NetCDF) and ``--plot FILE``; the
fold-of-cycles curve of every generalised-Hopf point and the shaded regions
"squeal possible although linearly stable" and "contact lost" (``--folds``, the
default; ``--fold-points`` slices each, progress on stderr).
"""

from __future__ import annotations

import json
import sys
from typing import Annotated, Optional

import typer

from ._options import (PLOT_SUFFIXES, FormatOpt, ModelOpt, OutFormat, ParamsOpt, PresetOpt, ProgressOpt, SetOpt,
                       refuse_set_of_axes, space_from)

__all__ = ["register"]


def region(
    x: Annotated[str, typer.Option("--x", help="NAME=START:STOP[:log] (horizontal axis).")],
    y: Annotated[str, typer.Option("--y", help="NAME=START:STOP[:log] (vertical axis).")],
    model: ModelOpt = None, preset: PresetOpt = None, params: ParamsOpt = None, set_: SetOpt = None,
    fmt: FormatOpt = OutFormat.text,
    out: Annotated[Optional[str], typer.Option("--out", help="NetCDF file of the curves (.nc).")] = None,
    plot: Annotated[Optional[str], typer.Option("--plot", help="Also draw the diagram (PNG, SVG or PDF).")] = None,
    seeds: Annotated[int, typer.Option("--seeds", min=1, max=100,
                                       help="Paths in each direction whose crossings seed the curves.")] = 5,
    max_points: Annotated[int, typer.Option("--max-points", min=2, max=10000,
                                            help="Largest number of curve points each way from a seed.")] = 200,
    grid: Annotated[int, typer.Option("--grid", min=2, max=2000,
                                      help="Points per axis of the certified stability map.")] = 41,
    folds: Annotated[bool, typer.Option("--folds/--no-folds",
                                        help="Fold-of-cycles curves from each generalised-Hopf point and the "
                                             "shaded regions (one cycle branch per slice).")] = True,
    fold_points: Annotated[int, typer.Option("--fold-points", min=1, max=50,
                                             help="Slices (cycle branches) per generalised-Hopf point.")] = 6,
    fold_contact: Annotated[str, typer.Option(
        "--fold-contact", help="stop: a slice whose cycles lose contact ends there (the brake); bilateral: followed "
                               "on to the fold of the smooth bilateral equations (as AUTO-07p).")] = "stop",
    progress: ProgressOpt = None,
) -> None:
    """Squeal regions in two parameters: Hopf curves coloured super/subcritical (l1 with the pads' true rates),
    generalised-Hopf, Bogdanov-Takens, zero-Hopf and double-Hopf points, on the certified stability map; the
    fold-of-cycles curve from each generalised-Hopf point, shading "squeal possible although linearly stable"
    and "contact lost"."""
    from ..analysis.maps import parse_axis
    from ..outputs import atomic_write, check_output
    from ..region import region_diagram

    from ..errors import ParameterError

    axes = []
    for text, opt in ((x, "--x"), (y, "--y")):
        try:
            axes.append(parse_axis(text, with_num=False))
        except ParameterError as exc:
            raise ParameterError(f"{opt}: {exc}", parameter=opt) from None
    ax_x, ax_y = axes
    if ax_x.name == ax_y.name:
        raise ParameterError(f"The options --x and --y must vary two different parameters; got {ax_x.name!r} for "
                             "both", parameter="--y")
    refuse_set_of_axes(set_, {ax_x.name: "--x", ax_y.name: "--y"})
    if fold_contact not in ("stop", "bilateral"):
        raise ParameterError(f"The option --fold-contact must be stop or bilateral; got {fold_contact!r}",
                             parameter="--fold-contact")
    if out:
        check_output(out, what="--out", suffixes=(".nc",))
    if plot:
        check_output(plot, what="--plot", suffixes=PLOT_SUFFIXES)
    space = space_from(model, preset, params, set_, axes={ax_x.name: "--x", ax_y.name: "--y"})
    from ..api import engine

    from ._progress import progress as _progress

    with _progress("region (fold-of-cycles curves)", progress if folds else False) as cb:
        r = region_diagram(engine(space), space, ax_x, ax_y, seeds=seeds, max_points=max_points, grid=grid,
                           folds=folds, fold_points=fold_points, fold_contact=fold_contact, progress=cb)
    if out:
        with atomic_write(out, what="--out") as tmp:
            r.to_dataset().to_netcdf(str(tmp), engine="scipy")
    if plot:
        with atomic_write(plot, what="--plot") as tmp:
            r.plot().savefig(tmp, dpi=300)
    if fmt == OutFormat.json:
        sys.stdout.write(json.dumps(r.to_dict(), indent=2) + "\n")
    else:
        sys.stdout.write(r.text())


def register(app: typer.Typer) -> None:
    """Add ``region`` to ``app``.

    Parameters
    ----------
    app : typer.Typer
        The main application.
    """
    app.command("region")(region)
