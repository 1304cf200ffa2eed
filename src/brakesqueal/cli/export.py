"""``brakesqueal export`` (registered by :mod:`brakesqueal.cli`).

SymPy and the printers are imported inside the command.  The output path is
checked before any work and written atomically (:mod:`brakesqueal.outputs`).
"""

from __future__ import annotations

import sys
from enum import Enum
from typing import TYPE_CHECKING, Annotated, Optional, cast

import typer

from ._options import ModelOpt, ParamsOpt, PresetOpt, SetOpt, space_from, with_equations

if TYPE_CHECKING:
    from ..export import Target as _Target
    from ..export.model import What as _What
    from ..model.parameters import ParameterSpace

__all__ = ["register", "describe_source"]


class Target(str, Enum):
    latex = "latex"
    octave = "octave"
    c = "c"
    julia = "julia"
    python = "python"
    auto = "auto"


class What(str, Enum):
    nonlinear = "nonlinear"
    linear = "linear"


def describe_source(space: ParameterSpace, model: str | None, params: str | None, sets: list[str]) -> str:
    """Header description of the parameter options, e.g. ``model six-dof, preset six-dof, --set mu1=0.4``.

    Parameters
    ----------
    space : ParameterSpace
        The resolved space (:func:`brakesqueal.model.options.resolve_space`).
    model, params : str or None
        The ``--model`` and ``--params`` options.
    sets : list of str
        The ``--set`` options.

    Returns
    -------
    str
    """
    parts = []
    if model is not None:
        parts.append(f"model {space.model.name}")
    if params is not None:
        parts.append(f"file {params}")
    if space.label != "parameters":
        parts.append(f"preset {space.label}")
    if sets:
        parts.append("--set " + " ".join(sets))
    return ", ".join(parts)


def _export_cmd(
    to: Annotated[Target, typer.Option("--to", help="Output language: latex, octave (MATLAB), c, julia, python, or "
                                                    "auto (AUTO-07p's C user functions; needs --x and --y).")],
    out: Annotated[str, typer.Option("--out", help="Output file ('-' for stdout); its stem names the function.")],
    what: Annotated[
        What,
        typer.Option(
            "--what", help="nonlinear: residuals, pad solver, ODE right-hand side; linear: closed-form M, D, K about "
            "the zero state (refused unless that is the silent motion).",
        ),
    ] = What.nonlinear,
    model: ModelOpt = None, preset: PresetOpt = None, params: ParamsOpt = None, set_: SetOpt = None,
    x: Annotated[Optional[str], typer.Option("--x", help="auto: NAME=START:STOP[:log], AUTO's PAR(1) (the start "
                                                          "is the parameter's current value).")] = None,
    y: Annotated[Optional[str], typer.Option("--y", help="auto: NAME=START:STOP[:log], AUTO's PAR(2).")] = None,
) -> None:
    """Write any model's equations (nonlinear or closed-form linear) as C, Octave, Julia, Python or LaTeX, or as
    AUTO-07p's C user functions over two parameters (``--to auto --x ... --y ...``)."""
    from ..export import TARGETS, check_name, export_code
    from ..outputs import atomic_write, check_output

    if to is Target.auto:
        _export_auto(out, x, y, what, model, preset, params, set_)
        return
    if x is not None or y is not None:
        from ..errors import ParameterError

        raise ParameterError("The options --x and --y belong to --to auto", parameter="--x")
    suffix = TARGETS[to.value]
    path = None if out == "-" else check_output(out, what="--out", suffixes=(suffix,))
    name = "brakesqueal_model" if path is None else path.stem
    check_name(name, to.value)
    sets = list(set_ or [])
    space = with_equations(space_from(model, preset, params, sets), "export")
    source = describe_source(space, model, params, sets)
    # the enums' values are the literals export_code takes
    text = export_code(cast("_Target", to.value), cast("_What", what.value), space.resolve({}), name=name,
                       source=source)
    if path is None:
        sys.stdout.write(text)
        return
    with atomic_write(path, what="--out") as tmp:
        tmp.write_text(text, encoding="utf-8")
    print(f"wrote {path} ({to.value}, {what.value}, model {space.model.name})", file=sys.stderr)


def _export_auto(out: str, x: str | None, y: str | None, what: What, model: str | None, preset: str | None,
                 params: str | None, set_: list[str] | None) -> None:
    """``export --to auto``: :func:`brakesqueal.region.auto.auto_source` over ``--x``, ``--y`` from the parameters'
    current values (the silent motion there is AUTO's starting point)."""
    from ..analysis.maps import parse_axis
    from ..errors import ParameterError
    from ..outputs import atomic_write, check_output

    if what is not What.nonlinear:
        raise ParameterError("The option --what must be nonlinear with --to auto (AUTO continues the vector field)",
                             parameter="--what")
    axes = []
    for text, opt in ((x, "--x"), (y, "--y")):
        if text is None:
            raise ParameterError(f"--to auto needs {opt} NAME=START:STOP[:log] (AUTO's "
                                 f"PAR({1 if opt == '--x' else 2}))", parameter=opt)
        try:
            axes.append(parse_axis(text, with_num=False))
        except ParameterError as exc:
            raise ParameterError(f"{opt}: {exc}", parameter=opt) from None
    ax_x, ax_y = axes
    path = None if out == "-" else check_output(out, what="--out", suffixes=(".c",))
    space = with_equations(space_from(model, preset, params, list(set_ or [])), "export")
    for ax, opt in ((ax_x, "--x"), (ax_y, "--y")):
        if ax.name not in space.settable():
            space.resolve({ax.name: 1.0})  # the one message for unknown or tied names
    x0, y0 = space.value(ax_x.name), space.value(ax_y.name)
    for ax, v, opt in ((ax_x, x0, "--x"), (ax_y, y0, "--y")):
        if not min(ax.start, ax.stop) <= v <= max(ax.start, ax.stop):
            raise ParameterError(f"{opt}: the current value {ax.name} = {v:g} (AUTO's start) must lie in "
                                 f"[{min(ax.start, ax.stop):g}, {max(ax.start, ax.stop):g}]; set it with --set",
                                 parameter=opt)
    from ..api import engine
    from ..region.auto import auto_source

    text = auto_source(engine(space), space, ax_x, ax_y, x0, y0)
    if path is None:
        sys.stdout.write(text)
        return
    with atomic_write(path, what="--out") as tmp:
        tmp.write_text(text, encoding="utf-8")
    print(f"wrote {path} (AUTO-07p user functions, PAR(1) = {ax_x.name}, PAR(2) = {ax_y.name} scaled to the unit "
          f"box, model {space.model.name})", file=sys.stderr)


def register(app: typer.Typer) -> None:
    """Add the ``export`` command to the application.

    Parameters
    ----------
    app : typer.Typer
        The main application (:data:`brakesqueal.cli.app`).
    """
    app.command("export")(_export_cmd)
