"""``brakesqueal import | box | reduce``: finite-element models given by coefficient matrices."""

from __future__ import annotations

import sys
from typing import Annotated, Optional

import typer

from ._options import NUMBER, FormatOpt, ModelOpt, OutFormat, ParamsOpt, PresetOpt, ProgressOpt, SetOpt, space_from

__all__ = ["register", "import_cmd", "box_cmd", "reduce_cmd"]


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


def _range(text: str, option: str, *, low_inf: bool = False) -> tuple[float, float]:
    """``LO:HI`` (expressions; ``-inf``/``inf`` allowed) as two floats with ``LO < HI``."""
    from ..errors import ParameterError
    from ..model.expressions import evaluate

    lo, sep, hi = text.partition(":")
    if not sep or not lo.strip() or not hi.strip():
        raise ParameterError(f"{option} must be LO:HI; got {text!r}", parameter=option)
    a = evaluate(lo.strip().replace("-inf", "-(inf)"), {}, what=f"{option} low end")
    b = evaluate(hi.strip(), {}, what=f"{option} high end")
    if not a < b:
        raise ParameterError(f"{option} needs LO < HI; got {text!r}", parameter=option)
    return a, b


BoxReOpt = Annotated[str, typer.Option("--re", help="Range of Re(lambda) [1/s], LO:HI (e.g. -50:inf).")]
BoxFreqOpt = Annotated[str, typer.Option("--freq", help="Frequency range [Hz], F1:F2 with 0 <= F1 < F2.")]


def box_cmd(
    re: BoxReOpt, freq: BoxFreqOpt, model: ModelOpt = None, preset: PresetOpt = None, params: ParamsOpt = None,
    set_: SetOpt = None, fmt: FormatOpt = OutFormat.text,
    max_shifts: Annotated[int, typer.Option("--max-shifts", min=1, max=500,
                                            help="Most shift-and-invert runs before the box counts as not "
                                                 "covered (verdict undecided).")] = 40,
    progress: ProgressOpt = None,
) -> None:
    """Eigenvalues of a large matrix model in a box (Re range x frequency range) with error bounds: "k unstable
    modes in [f1, f2] Hz", "stable in box", or "undecided" naming what was not resolved."""
    import json

    from ..api import box_eigenvalues, engine as _engine
    from ._progress import progress as _progress

    box_re, box_f = _range(re, "--re"), _range(freq, "--freq")
    p = space_from(model, preset, params, set_).resolve({})
    engine = _engine(p)
    with _progress("box", progress) as cb:
        r = box_eigenvalues(p, re=box_re, freq=box_f, max_shifts=max_shifts, progress=lambda i, n: cb(i / max(n, 1)))
    rows = [{"re": float(z.real), "im": float(z.imag), "frequency_hz": float(z.imag / (2 * 3.141592653589793)),
             "bound": float(b)} for z, b in zip(r.eigenvalues, r.bounds)]
    if fmt == OutFormat.json:
        sys.stdout.write(json.dumps({"model": p.model.name, "parameters": p.to_json_dict(), "box": list(r.box),
                                     "verdict": r.verdict, "complete": r.complete, "unstable": r.unstable,
                                     "undecided": r.undecided, "eigenvalues": rows, "notes": list(r.notes),
                                     "shifts": len(r.shifts)}, indent=2) + "\n")
        return
    lo, hi, f1, f2 = r.box
    sys.stdout.write(f"Model '{p.model.name}' ({engine.caps.n} DOF): eigenvalues with Re in [{lo:g}, {hi:g}] 1/s "
                     f"and f in [{f1:g}, {f2:g}] Hz ({len(r.shifts)} shifts)\n")
    sys.stdout.write("  Re(lambda) [1/s]    frequency [Hz]   error bound [1/s]\n")
    for row in rows:
        sys.stdout.write(f"  {row['re']: .6e}  {row['frequency_hz']:14.6f}   {row['bound']:.1e}\n")
    sys.stdout.write(f"verdict: {r.verdict}" + ("" if r.complete else " (the box is not fully covered)") + "\n")
    for n in r.notes:
        sys.stdout.write(f"  note: {n}\n")


def reduce_cmd(
    along: Annotated[str, typer.Option("--along", help="Spin samples NAME=START:STOP:N (e.g. Omega=2*pi:8*pi:5).")],
    re: BoxReOpt, freq: BoxFreqOpt,
    out: Annotated[str, typer.Option("--out", "-o", help="The reduced model file (.toml; its matrices go to "
                                                          "the .mat of the same name).")],
    model: ModelOpt = None, preset: PresetOpt = None, params: ParamsOpt = None, set_: SetOpt = None,
    dim: Annotated[Optional[int], typer.Option("--dim", "-r", min=1, max=2000,
                                               help="Reduced dimension (default: every singular value above "
                                                    "--tol of the largest).")] = None,
    tol: Annotated[float, typer.Option("--tol", **NUMBER, help="Relative singular-value cut-off, in [0, 1].")] = 1e-10,
    checks: Annotated[int, typer.Option("--checks", min=0, max=50, help="Speeds between the samples at which "
                                        "the reduced model is compared with the full one.")] = 2,
    right_only: Annotated[bool, typer.Option("--right-only", help="A basis of the right eigenvectors alone "
                                             "(smaller, but its eigenvalue errors are first order).")] = False,
    fmt: FormatOpt = OutFormat.text, progress: ProgressOpt = None,
) -> None:
    """Reduce a large matrix model along its spin (POD of its box eigenvectors, the published method) and write
    the small model, which every command then analyses at dense speed; its error is measured and printed."""
    import json

    import numpy as np

    from ..analysis.maps import parse_axis
    from ..api import engine as _engine, reduce_matrix_model
    from ..model.matrices import write_matrix_model
    from ..outputs import check_output
    from ._progress import progress as _progress

    from ..errors import ParameterError

    if not 0.0 <= tol <= 1.0:
        raise ParameterError(f"--tol must be in [0, 1]; got {tol!r}", parameter="--tol")
    check_output(out, what="--out", suffixes=(".toml",))
    ax = parse_axis(along)
    space = space_from(model, preset, params, set_, axes={ax.name: "--along"})
    engine = _engine(space)
    samples = [float(v) for v in ax.values()]
    with _progress("reduce", progress) as cb:
        red = reduce_matrix_model(space, samples, re=_range(re, "--re"), freq=_range(freq, "--freq"), r=dim,
                                  tol=tol, checks=checks, left=not right_only,
                                  progress=lambda i, n: cb(i / max(n, 1)))
    write_matrix_model(red.spec, out)
    if fmt == OutFormat.json:
        sys.stdout.write(json.dumps({**red.to_dict(), "out": out}, indent=2, allow_nan=False,
                                    default=lambda v: None) + "\n")
        return
    sys.stdout.write(f"wrote {out}: model '{red.spec.name}', {red.spec.n} DOF (from {engine.caps.n}), basis from "
                     f"{len(samples)} samples of {ax.name} in [{float(np.min(samples)):g}, {float(np.max(samples)):g}]"
                     f" ({red.basis})\n")
    for c in red.checks:
        sys.stdout.write(f"  check at {ax.name} = {c['Omega']:.6g}: {c['count_full']} box eigenvalues (full), "
                         f"{c['count_reduced']} (reduced), largest relative error {c['max_rel_error']:.1e}, "
                         f"real-part error {c['max_re_error']:.1e} 1/s (smallest |Re| {c['min_abs_re']:.1e})\n")
    if red.checks and not red.reliable:
        from ._options import note

        note("the reduced model's real parts are less accurate than the full model's growth rates: its verdicts "
             "may differ from the full model's; take more samples or a larger --dim")
    sys.stdout.write(f"next: brakesqueal map --model {out} --x {ax.name}=... --y ... --out map.nc\n")


def register(app: typer.Typer) -> None:
    """Add ``import``, ``box`` and ``reduce`` to the application."""
    app.command("import")(import_cmd)
    app.command("box")(box_cmd)
    app.command("reduce")(reduce_cmd)
