"""``brakesqueal export`` (registered by :mod:`brakesqueal.cli`).

SymPy and the printers are imported inside the command.
"""

from __future__ import annotations

import sys
from enum import Enum
from pathlib import Path
from typing import Annotated, Optional

import typer

__all__ = ["register"]


class Target(str, Enum):
    latex = "latex"
    octave = "octave"
    c = "c"
    julia = "julia"
    python = "python"


class What(str, Enum):
    nonlinear = "nonlinear"
    linear = "linear"


def _export_cmd(
    to: Annotated[Target, typer.Option("--to", help="Output language: latex, octave (also MATLAB), c, julia or python.")],
    out: Annotated[str, typer.Option("--out", help="Output file ('-' for stdout); its stem names the Octave function.")],
    what: Annotated[
        What,
        typer.Option(
            "--what", help="nonlinear: residuals, pad residuals, ODE right-hand side; linear: closed-form Mbar, Dbar, "
            "Kbar about the trivial silent motion.",
        ),
    ] = What.nonlinear,
    preset: Annotated[
        Optional[str], typer.Option("--preset", help="Named parameter template for parameters() (default paper-fig2).")
    ] = None,
    params: Annotated[Optional[str], typer.Option("--params", help="TOML parameter file for parameters().")] = None,
    set_: Annotated[
        Optional[list[str]], typer.Option("--set", help="Override NAME=VALUE (repeatable; VALUE may be 'inf').")
    ] = None,
) -> None:
    """Write the equations (nonlinear or closed-form linear) as C, Octave, Julia, Python or LaTeX."""
    from .errors import ParameterError
    from .export import TARGETS, export_code
    from .export.model import _source
    from .parameters import resolve_parameters

    p = resolve_parameters(preset, params, list(set_ or []))
    path = None if out == "-" else Path(out)
    if path is not None and path.suffix != TARGETS[to.value]:
        raise ParameterError(f"The option '--out' must end in {TARGETS[to.value]} for --to {to.value}; got {out!r}")
    name = "brakesqueal_model" if path is None else path.stem
    text = export_code(to.value, what.value, p, name=name, source=_source(preset, params, list(set_ or [])))  # type: ignore[arg-type]
    if path is None:
        sys.stdout.write(text)
        return
    try:
        path.write_text(text)
    except OSError as exc:
        raise ParameterError(f"The option '--out' names a file that cannot be written: {out!r} ({exc.strerror})") from None
    print(f"wrote {path} ({to.value}, {what.value})", file=sys.stderr)


def register(app: typer.Typer, bench_app: typer.Typer) -> None:
    """Add the ``export`` command to the application.

    Parameters
    ----------
    app : typer.Typer
        The main application (:data:`brakesqueal.cli.app`).
    bench_app : typer.Typer
        The ``bench`` sub-application (unused: export has no benchmark).
    """
    app.command("export")(_export_cmd)
