"""``brakesqueal export`` (registered by :mod:`brakesqueal.cli`).

SymPy and the printers are imported inside the command.  The output path is
checked before any work and written atomically (:mod:`brakesqueal.outputs`).
"""

from __future__ import annotations

import sys
from enum import Enum
from typing import TYPE_CHECKING, Annotated, cast

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
    to: Annotated[Target, typer.Option("--to", help="Output language: latex, octave (MATLAB), c, julia or python.")],
    out: Annotated[str, typer.Option("--out", help="Output file ('-' for stdout); its stem names the function.")],
    what: Annotated[
        What,
        typer.Option(
            "--what", help="nonlinear: residuals, pad solver, ODE right-hand side; linear: closed-form M, D, K about "
            "the zero state (refused unless that is the silent motion).",
        ),
    ] = What.nonlinear,
    model: ModelOpt = None, preset: PresetOpt = None, params: ParamsOpt = None, set_: SetOpt = None,
) -> None:
    """Write any model's equations (nonlinear or closed-form linear) as C, Octave, Julia, Python or LaTeX."""
    from ..export import TARGETS, check_name, export_code
    from ..outputs import atomic_write, check_output

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


def register(app: typer.Typer) -> None:
    """Add the ``export`` command to the application.

    Parameters
    ----------
    app : typer.Typer
        The main application (:data:`brakesqueal.cli.app`).
    """
    app.command("export")(_export_cmd)
