"""``brakesqueal modes``: mode-coupling diagram along a parameter, for any model."""

from __future__ import annotations

import json
import sys
from typing import Annotated, Optional

import typer

from ..errors import ParameterError
from ._options import (PLOT_SUFFIXES, FormatOpt, ModelOpt, OutFormat, ParamsOpt, PresetOpt, ProgressOpt, SetOpt,
                       refuse_set_of_axes, space_from)

__all__ = ["register"]


def modes(
    along: Annotated[str, typer.Option("--along", help="NAME=START:STOP[:log], the parameter path.")],
    num: Annotated[int, typer.Option("--num", help="Points of the path.", min=3, max=100_000)] = 200,
    model: ModelOpt = None, preset: PresetOpt = None, params: ParamsOpt = None, set_: SetOpt = None,
    fmt: FormatOpt = OutFormat.text,
    out: Annotated[Optional[str], typer.Option("--out", help="Write the tracked modes (NetCDF, .nc).")] = None,
    plot: Annotated[Optional[str], typer.Option("--plot", help="Draw the diagram (PNG, SVG or PDF).")] = None,
    progress: ProgressOpt = None,
) -> None:
    """Frequencies and real parts of every mode along a path, tracked by continuity; coalescences and crossings."""
    from ..analysis.maps import parse_axis, resolution_problem
    from ..analysis.modes import modes_along
    from ..outputs import atomic_write, check_output

    axis = parse_axis(along, with_num=False)
    refuse_set_of_axes(set_, {axis.name: "--along"})
    problem = resolution_problem(axis.start, axis.stop, num, axis.log)
    if problem:
        raise ParameterError(f"--along {axis.name} with --num {num}: {problem}", parameter=axis.name)
    if out:
        check_output(out, what="--out", suffixes=(".nc",))
    if plot:
        check_output(plot, what="--plot", suffixes=PLOT_SUFFIXES)
    space = space_from(model, preset, params, set_, axes={axis.name: "--along"})
    from ..codegen import build
    from ._progress import progress as _progress

    engine = build(space.model)  # the entry point's engine, passed down
    with _progress("modes", progress) as cb:  # a long path (e.g. 100000 points of eight-dof) takes minutes
        tr = modes_along(engine, space, axis.name, axis.start, axis.stop, num=num, log=axis.log, progress=cb)
    if out:
        with atomic_write(out, what="--out") as tmp:
            tr.to_xarray().to_netcdf(tmp, engine="scipy")
    if plot:
        with atomic_write(plot, what="--plot") as tmp:
            tr.plot().savefig(tmp, dpi=150)
    if fmt == OutFormat.json:
        sys.stdout.write(json.dumps({"parameter": tr.parameter, "model": tr.model, "range": [axis.start, axis.stop],
                                     "coalescences": tr.coalescences, "crossings": tr.crossings}, indent=2) + "\n")
        return
    lines = [f"{tr.eigenvalues.shape[1]} modes of model '{tr.model}' "
             f"along {tr.parameter} in [{axis.start:g}, {axis.stop:g}] ({num} points)"]
    for c in tr.coalescences:
        lines.append(f"  modes {c['modes'][0]} and {c['modes'][1]} {c['kind']} at {tr.parameter} = {c['value']:.8g} "
                     f"({c['frequency_hz']:.6g} Hz)")
    for c in tr.crossings:
        lines.append(f"  mode {c['mode']} {c['direction']} at {tr.parameter} = {c['value']:.8g}")
    if not tr.coalescences and not tr.crossings:
        lines.append("  no coalescence and no stability change")
    sys.stdout.write("\n".join(lines) + "\n")


def register(app: typer.Typer) -> None:
    """Add ``modes`` to the application."""
    app.command("modes")(modes)
