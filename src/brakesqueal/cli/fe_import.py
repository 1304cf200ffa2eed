"""``brakesqueal import``: a model file from finite-element coefficient matrices."""

from __future__ import annotations

import sys
from typing import Annotated, Optional

import typer

__all__ = ["register", "import_cmd"]


def import_cmd(
    files: Annotated[list[str], typer.Argument(help="Matrix files: .mat, Matrix Market, Harwell-Boeing, ABAQUS .mtx, "
                                                    "CalculiX .sti/.mas, Nastran DMIG (.bdf/.pch), OP4.")],
    coefficient: Annotated[Optional[list[str]], typer.Option(
        "--coefficient", "-c", help="M=EXPR, D=EXPR, K=EXPR (repeatable): a sum of matrix names with factors over "
                                    "the parameters, e.g. 'D=D1 + DR/Omega + Omega*DG'; NAME=NUMBER declares a "
                                    "parameter with its default.")] = None,
    parameter: Annotated[Optional[list[str]], typer.Option(
        "--parameter", "-p", help="NAME=VALUE: a parameter's default (every other name in the coefficients that "
                                  "is not a matrix is a parameter with default 1).")] = None,
    out: Annotated[str, typer.Option("--out", "-o", help="The model file to write (.toml).")] = "model.toml",
    fmt: Annotated[Optional[str], typer.Option("--format", help="Format of the files (default: from each file): "
                                               "mat, mm, hb, abaqus, calculix, dmig, op4.")] = None,
    name: Annotated[Optional[str], typer.Option("--name", help="Model name (default: the first file's stem).")] = None,
    variables: Annotated[Optional[list[str]], typer.Option(
        "--variable", help="Keep only these matrices (repeatable; default: every matrix of the files).")] = None,
    spin: Annotated[str, typer.Option("--spin", help="The parameter that is the disk speed [rad/s].")] = "Omega",
) -> None:
    """Write a model file from coefficient matrices: (λ² M + λ D + K) x = 0, every term's factor a function of
    the parameters; every linear command then takes it with --model."""
    import os

    from ..errors import ParameterError
    from ..model.matrices import COEFFICIENTS, import_matrices, matrix_model_toml
    from ..model.parameters import parse_sets
    from ..outputs import atomic_write, check_output

    coeffs: dict[str, str] = {}
    params: dict[str, float] = {}
    for text in coefficient or []:
        key, sep, value = text.partition("=")
        key, value = key.strip(), value.strip()
        if not sep or not key or not value:
            raise ParameterError(f"malformed --coefficient {text!r}: expected M=EXPR, D=EXPR, K=EXPR or "
                                 "NAME=NUMBER", parameter="--coefficient")
        if key in COEFFICIENTS:
            if key in coeffs:
                raise ParameterError(f"--coefficient {key} is given more than once", parameter="--coefficient")
            coeffs[key] = value
            continue
        try:
            params[key] = float(value)
        except ValueError:
            raise ParameterError(f"--coefficient {text!r}: only M, D and K take expressions; another name "
                                 "declares a parameter with a number (e.g. s=1)", parameter="--coefficient") from None
    missing = [c for c in COEFFICIENTS if c not in coeffs]
    if missing:
        raise ParameterError(f"import needs --coefficient for {', '.join(missing)} (e.g. --coefficient 'M=M')",
                             parameter="--coefficient")
    for k, v in parse_sets(list(parameter or []), option="--parameter").items():
        params[k] = float(v) if not isinstance(v, str) else _number(v, k)
    for f in files:
        if os.path.abspath(f) == os.path.abspath(out):
            raise ParameterError(f"--out {out!r} is one of the matrix files read", parameter="--out")
    target = check_output(out, what="--out", suffixes=(".toml",))
    spec = import_matrices(files, coeffs, parameters=params, name=name, format=fmt, variables=variables, spin=spin)
    text = matrix_model_toml(spec, base=os.path.dirname(os.path.abspath(str(target))))
    with atomic_write(target, what="model file") as tmp:
        tmp.write_text(text, encoding="utf-8")
    unit = ", ".join(f"{k} = {v:g}" for k, v in spec.parameters.items()) or "none"
    sys.stdout.write(f"wrote {out}: model '{spec.name}', {spec.n} DOF{' (sparse)' if spec.sparse else ''}, "
                     f"matrices {', '.join(spec.matrices)}; parameters (defaults) {unit}\n"
                     f"next: brakesqueal linearize --model {out}"
                     + (f" --set {spec.spin}=..." if spec.spin else "") + "\n")


def _number(text: str, name: str) -> float:
    from ..model.expressions import evaluate

    return evaluate(text, {}, what=f"--parameter {name}")


def register(app: typer.Typer) -> None:
    """Add ``import`` to the application."""
    app.command("import")(import_cmd)
