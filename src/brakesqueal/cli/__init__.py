"""Command-line interface: ``brakesqueal derive | linearize | eigen | map | simulate | ...``.

One module per command group; the options ``--model/--preset/--params/--set``
mean the same on every command (:mod:`._options`).  Every user error is one
line on stderr with exit status 2, an interrupt exits with 130; heavy modules
are imported inside the commands so that ``--help`` and a warm ``linearize``
start fast.
"""

from __future__ import annotations

import sys
from enum import Enum
from typing import TYPE_CHECKING, Annotated, Optional

import typer
from typer.exceptions import Abort, Exit, TyperException

from ..errors import BrakesquealError
from ._options import FormatOpt, ModelOpt, NoCacheOpt, OutFormat, ParamsOpt, PresetOpt, SetOpt, space_from

if TYPE_CHECKING:
    from typer.models import CommandInfo, TyperInfo

__all__ = ["app", "main"]

app = typer.Typer(
    name="brakesqueal",
    help="Derive, linearize and analyse wobbling-disk models of disk-brake squeal.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)


def _version(value: bool) -> None:
    if value:
        from .. import __version__

        print(f"brakesqueal {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[Optional[bool], typer.Option("--version", callback=_version, is_eager=True,
                                                    help="Print the version and exit.")] = None,
) -> None:
    """Derive, linearize and analyse wobbling-disk models of disk-brake squeal.

    Models: brakesqueal list models; presets: brakesqueal list presets; one of them: brakesqueal show NAME.
    """


class Case(str, Enum):
    """Closed-form cases of the paper's model."""

    general = "general"
    symmetric = "symmetric"
    asymmetric_friction = "asymmetric-friction"
    minimal = "minimal"


class DeriveFormat(str, Enum):
    """Formats of ``derive``."""

    text = "text"
    latex = "latex"
    json = "json"


class PadRates(str, Enum):
    """Treatment of the massless pads' tangential rates."""

    kept = "kept"
    quasi_static = "quasi-static"


@app.command()
def derive(
    case: Annotated[Case, typer.Option("--case", help="Closed-form case of the paper's model.")] = Case.general,
    fmt: Annotated[DeriveFormat, typer.Option("--format", help="Output format.")] = DeriveFormat.text,
    model: ModelOpt = None,
    no_cache: NoCacheOpt = False,
) -> None:
    """Print the symbolic M, D, K about the zero state (eqs. 51-54, 59-61 for the paper's model)."""
    if model is not None:
        from ..model import resolve_model
        from ..render import render_model_closed_form

        sys.stdout.write(render_model_closed_form(resolve_model(model), fmt.value).rstrip("\n") + "\n")
        return
    # the paper's closed forms ship as text checked against the live derivation (no SymPy needed)
    from .closed_forms import shipped_text

    text = None if no_cache else shipped_text(case.value, fmt.value)
    if text is None:
        from ..codegen import cache
        from ..render import render_closed_form

        text = cache.cached_text("closed-forms", f"{case.value}.{fmt.value}",
                                 lambda: render_closed_form(case.value, fmt.value), use_cache=not no_cache)
    sys.stdout.write(text if text.endswith("\n") else text + "\n")


@app.command()
def linearize(
    model: ModelOpt = None, preset: PresetOpt = None, params: ParamsOpt = None, set_: SetOpt = None,
    fmt: FormatOpt = OutFormat.text,
    pad_rates: Annotated[PadRates, typer.Option("--pad-rates", help="Massless pads' tangential rates: kept "
                                                "(exact) or quasi-static (ldot := 0).")] = PadRates.kept,
    no_cache: NoCacheOpt = False,
) -> None:
    """Find the silent motion, linearize (eqs. 46-48) and print M, D, K, the eigenvalues and the verdict."""
    from ..analysis.linear import linearize as _linearize
    from ..codegen import build
    from ..render import render_linear_model

    p = space_from(model, preset, params, set_).resolve({})
    lm = _linearize(build(p.model, use_cache=not no_cache), p, pad_rates=pad_rates.value)
    sys.stdout.write(render_linear_model(lm, fmt.value))


@app.command()
def eigen(
    model: ModelOpt = None, preset: PresetOpt = None, params: ParamsOpt = None, set_: SetOpt = None,
    fmt: FormatOpt = OutFormat.text,
    mode: Annotated[int, typer.Option("--mode", help="Mode whose Re(lambda) is attributed to matrix entries "
                                      "(0 = least stable).", min=0)] = 0,
) -> None:
    """Eigen-analysis at one point: frequencies, damping ratios, mode shapes, sensitivities, attribution of Re λ."""
    from ..api import eigen_analysis
    from ..render import render_eigen

    ea = eigen_analysis(space_from(model, preset, params, set_).resolve({}))
    n_modes = int(ea.eigenvalues.size)
    if mode >= n_modes:
        from ..errors import ParameterError

        raise ParameterError(f"--mode must be in [0, {n_modes - 1}] (the {n_modes} eigenvalues listed, 0 = least "
                             f"stable); got {mode}", parameter="--mode")
    sys.stdout.write(render_eigen(ea, fmt.value, mode=mode))


class ListWhat(str, Enum):
    """What ``list`` lists."""

    models = "models"
    presets = "presets"


@app.command("list")
def list_(what: Annotated[ListWhat, typer.Argument(help="models or presets")],
          fmt: FormatOpt = OutFormat.text) -> None:
    """List the built-in models or presets with a one-line description."""
    import json

    from ..model import get_model, get_preset
    from ..model.library import MODELS, preset_names

    if what == ListWhat.models:
        rows = []
        for name in MODELS:
            spec = get_model(name)
            from ..codegen import build

            rows.append({"name": name, "coordinates": list(build(spec).caps.coords),
                         "presets": spec.preset_names(), "description": spec.description})
        from ..model.fe_library import FE_DOF, FE_MODELS

        fe: list[dict[str, object]] = [{"name": name, "kind": "matrices", "dof": FE_DOF[name], "presets": [name],
               "description": FE_MODELS[name][3]} for name in FE_MODELS]
        if fmt == OutFormat.json:
            sys.stdout.write(json.dumps([*rows, *fe], indent=2) + "\n")
        else:
            for r in rows:
                sys.stdout.write(f"{r['name']:<13} {len(r['coordinates'])} DOF  {r['description']}\n")
            for f in fe:
                sys.stdout.write(f"{f['name']:<13} {f['dof']} DOF  (coefficient matrices) {f['description']}\n")
        return
    out = []
    for name in preset_names():
        pr = get_preset(name)
        out.append({"name": name, "model": pr.bound_model.name, "free": list(pr.free),
                    "description": pr.description})
    if fmt == OutFormat.json:
        sys.stdout.write(json.dumps(out, indent=2) + "\n")
    else:
        for r in out:
            sys.stdout.write(f"{r['name']:<14} model {r['model']:<13} free: {', '.join(r['free'][:6])}"
                             f"{' ...' if len(r['free']) > 6 else ''}\n")


@app.command()
def show(name: Annotated[str, typer.Argument(help="A preset or a model (built-in name or TOML file).")],
         fmt: FormatOpt = OutFormat.text) -> None:
    """Show a preset's free, fixed and tied parameters (units, defaults) or a model's components and presets."""
    import json

    from ..errors import ParameterError
    from ..model import get_preset, resolve_model

    import os

    try:
        if name.lower().endswith(".toml") or os.path.isfile(name):
            pr = resolve_model(name).get_preset()  # a model file: its own error (TOML syntax, a bad field)
        else:
            pr = get_preset(name)
    except ParameterError:
        if name.lower().endswith(".toml") or os.path.isfile(name):
            raise
        try:
            pr = resolve_model(name).get_preset()
        except ParameterError:
            from ..model.library import MODELS, preset_names
            from ..suggest import did_you_mean

            raise ParameterError(
                f"'{name}' is neither a preset nor a model{did_you_mean(name, [*preset_names(), *MODELS])}"
                f"; see brakesqueal list presets / list models"
            ) from None
    if fmt == OutFormat.json:
        sys.stdout.write(json.dumps({
            "name": pr.name, "model": pr.bound_model.name, "description": pr.description, "reference": pr.reference,
            **{k: {n: {"value": v if isinstance(v, str) else float(v), "unit": pr.unit(n),
                       "description": pr.describe_name(n)} for n, v in getattr(pr, k).items()}
               for k in ("free", "fixed")},
            "tied": dict(pr.tied)}, indent=2) + "\n")
        return
    sys.stdout.write(pr.describe() + "\n")
    if pr.name == pr.bound_model.name:
        spec = pr.bound_model
        from ..model.matrices import MatrixSpec

        if isinstance(spec, MatrixSpec):
            sys.stdout.write(f"  given by coefficient matrices: {spec.n} DOF{' (sparse)' if spec.sparse else ''}, "
                             f"matrices {', '.join(spec.matrices)}\n"
                             + "".join(f"  {c} = {spec.coefficients[c]}\n" for c in ("M", "D", "K")))
            return
        sys.stdout.write(f"  components: {len(spec.pads)} pad(s) ({', '.join(p.name for p in spec.pads)})"
                         + (f", caliper(s) {', '.join(c.name for c in spec.calipers)}" if spec.calipers else "")
                         + f"; presets: {', '.join(spec.preset_names())}\n")


def _register_plugins() -> None:
    """Add the command groups that live in their own modules."""
    import importlib

    for name in (".stability", ".modes", ".sweep", ".plot", ".cache", ".simulate", ".export", ".explore", ".fe",
                 ".uq", ".region", ".robust", ".design"):
        mod = importlib.import_module(name, __package__)
        mod.register(app)


_register_plugins()

#: One complete sentence per command for the command list of ``brakesqueal --help`` (Click would cut the
#: docstring's first sentence at 45 characters); the command's own ``--help`` shows its whole docstring.
SUMMARIES: dict[str, str] = {
    "derive": "Symbolic M, D, K about the zero state (eqs. 51-61).",
    "linearize": "Silent motion, M, D, K, eigenvalues and verdict at one point.",
    "eigen": "Modes, damping, sensitivities and attribution of Re λ at one point.",
    "list": "List the built-in models or presets.",
    "show": "Parameters of a preset or components of a model.",
    "crossings": "Exact stability changes along a parameter path.",
    "critical-speed": "Onsets and re-stabilisations of squeal along Omega.",
    "hopf": "Hopf criticality (l1, cycle amplitude) at every crossing on a path.",
    "cycles": "Limit-cycle branch from a Hopf point, up to contact loss.",
    "map": "Stability map over two parameters (NetCDF and figure).",
    "reproduce": "Reproduce the paper's Figures 2 and 3.",
    "modes": "Mode-coupling diagram: every mode along a parameter path.",
    "sweep": "Resumable N-D parameter study into a Zarr store.",
    "plot": "Figure of a sweep store: map, slice or histograms.",
    "simulate": "Integrate the nonlinear equations; summary, NetCDF, WAV.",
    "export": "Write equations as LaTeX, Octave, C, Julia or Python.",
    "import": "A model file from finite-element coefficient matrices.",
    "box": "Eigenvalues of a large matrix model in a box, with bounds.",
    "reduce": "Reduce a large matrix model along Omega (POD).",
    "uq": "Squeal as a probability: Sobol indices and P(squeal) of a study.",
    "region": "Two-parameter squeal regions: Hopf curves, l1, special points.",
    "robust": "Certified robust design windows: stable for every point of a box.",
    "design": "Robust design: choose design variables that minimise P(squeal) or maximise the margin.",
    "cache": "Inspect or clear the code cache.",
    "explore": "The squeal explorer in the browser (live, offline).",
}


def _first_sentence(doc: str | None) -> str:
    import re

    text = " ".join((doc or "").strip().split("\n\n")[0].split())
    m = re.search(r"(?<!\bvs)(?<!\be\.g)(?<!\bi\.e)\.\s", text)  # not after an abbreviation
    return text if m is None else text[:m.start() + 1]


def _apply_summaries() -> None:
    """Give every command and group a complete one-line summary (sub-commands: their docstring's first sentence)."""
    infos: list[CommandInfo | TyperInfo] = [*app.registered_commands, *app.registered_groups]
    for info in infos:
        name = info.name or (info.callback.__name__ if info.callback else None)
        if name in SUMMARIES:
            info.short_help = SUMMARIES[name]
    for group in app.registered_groups:
        sub = group.typer_instance
        if sub is None:
            continue
        for cmd in sub.registered_commands:
            if not cmd.short_help:
                cmd.short_help = _first_sentence(cmd.help or (cmd.callback.__doc__ if cmd.callback else None))


_apply_summaries()


def _is_no_args_help(exc: BaseException) -> bool:
    """Whether ``exc`` is Click's "no arguments: show the help" signal (a group called without a sub-command)."""
    try:
        from typer._click.exceptions import NoArgsIsHelpError
    except ImportError:  # pragma: no cover - another Typer layout
        return type(exc).__name__ == "NoArgsIsHelpError"
    return isinstance(exc, NoArgsIsHelpError)


def _option_names(args: list[str]) -> dict[str, str]:
    """The invoked command's options by the name of its Python parameter (``{"sample_rate": "--sample-rate"}``)."""
    import typer.main

    cmd = typer.main.get_command(app)
    for a in args:
        sub = getattr(cmd, "commands", {}).get(a)
        if sub is None:
            if not a.startswith("-"):
                break
            continue
        cmd = sub
    names = {}
    for p in getattr(cmd, "params", []):
        longs = [o for o in getattr(p, "opts", []) if o.startswith("--")]
        if p.name and longs:
            names[p.name] = longs[0]
    return names


def _with_option_names(exc: BrakesquealError, args: list[str]) -> str:
    """The message of ``exc`` with the library's names of options (``'rtol'``) replaced by the command's
    (``'--rtol'``): only for a :class:`~brakesqueal.errors.ParameterError` about an option
    (its ``parameter``/``names``) that the invoked command has."""
    from ..errors import ParameterError

    msg = str(exc)
    if not isinstance(exc, ParameterError) or not exc.names:
        return msg
    try:
        options = _option_names(args)
    except Exception:  # noqa: BLE001 - the message as it is rather than no message
        return msg
    if "option '" not in msg and "options '" not in msg:
        return msg
    for name in exc.names:
        opt = options.get(name)
        if opt:
            msg = msg.replace(f"'{name}'", f"'{opt}'")
    return msg


def main(argv: list[str] | None = None) -> int:
    """Entry point: run the CLI, turning user errors into one stderr line (exit 2) and interrupts into exit 130.

    Parameters
    ----------
    argv : list of str, optional
        The arguments (default ``sys.argv[1:]``); none prints the help.

    Returns
    -------
    int
        The exit status: 0 success, 2 a user error, 130 an interrupt.
    """
    args = sys.argv[1:] if argv is None else list(argv)
    if not args:
        args = ["--help"]
    from ..interrupts import EXIT_AFTER_S, EXIT_STATUS, exit_now, interrupt_guard
    from ..outputs import guard_inputs

    program = argv is None
    try:
        # Ctrl-C within a second: the program (never a caller of main(argv) in its own process) ends a command
        # that does not unwind in EXIT_AFTER_S (not a sweep or uq: their Dask workers must be shut down), and then
        # skips the interpreter's slow teardown
        with interrupt_guard(exit_after=EXIT_AFTER_S if program and args[:1] not in (["sweep"], ["uq"]) else None), \
                guard_inputs(args):  # an output never replaces an input of the command (brakesqueal.outputs)
            rv = app(args=args, prog_name="brakesqueal", standalone_mode=False)
    except BrakesquealError as exc:
        print(f"brakesqueal: error: {_with_option_names(exc, args)}", file=sys.stderr)
        return 2
    except TyperException as exc:
        if _is_no_args_help(exc):  # a command group without its sub-command: its help, as the bare program
            sys.stdout.write(exc.format_message().rstrip("\n") + "\n")
            return 0
        msg = exc.format_message().replace("\n", " ")
        print(f"brakesqueal: error: {msg}", file=sys.stderr)
        return 2
    except Exit as exc:
        if exc.exit_code != EXIT_STATUS:
            return exc.exit_code
        rv = EXIT_STATUS  # typer's answer to a KeyboardInterrupt
    except (Abort, KeyboardInterrupt):
        rv = EXIT_STATUS
    if rv == EXIT_STATUS:
        print("brakesqueal: interrupted", file=sys.stderr)
        if program:
            exit_now(EXIT_STATUS)  # the program: outputs are complete or removed; no slow teardown
        return EXIT_STATUS
    return rv if isinstance(rv, int) else 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
