"""Command-line interface: ``brakesqueal derive | linearize | bench ...``.

Every user error is reported as one line on stderr with exit status 2; heavy
modules are imported inside the commands so that a warm ``linearize`` starts
fast.
"""

from __future__ import annotations

import sys
from enum import Enum
from typing import Annotated, Optional

import typer
from typer.exceptions import Abort, Exit, TyperException

from .errors import BrakesquealError

__all__ = ["app", "main"]

app = typer.Typer(
    name="brakesqueal",
    help="Derive, linearize and analyse wobbling-disk models of disk-brake squeal.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)
bench_app = typer.Typer(help="Measure speed on this machine against a baseline run in the same process.")
app.add_typer(bench_app, name="bench")


class Case(str, Enum):
    general = "general"
    symmetric = "symmetric"
    asymmetric_friction = "asymmetric-friction"
    minimal = "minimal"


class DeriveFormat(str, Enum):
    text = "text"
    latex = "latex"
    json = "json"


class OutFormat(str, Enum):
    text = "text"
    json = "json"


PresetOpt = Annotated[Optional[str], typer.Option("--preset", help="Named parameter template (default paper-fig2).")]
ParamsOpt = Annotated[Optional[str], typer.Option("--params", help="TOML parameter file.")]
SetOpt = Annotated[
    Optional[list[str]], typer.Option("--set", help="Override NAME=VALUE (repeatable; VALUE may be 'inf').")
]
ModelOpt = Annotated[
    Optional[str], typer.Option("--model", help="Model TOML file or built-in model name (see the model builder).")
]
NoCacheOpt = Annotated[bool, typer.Option("--no-cache", help="Derive in-process; do not read or write the cache.")]


@app.command()
def derive(
    case: Annotated[Case, typer.Option("--case", help="Which parameter case to print.")] = Case.general,
    fmt: Annotated[DeriveFormat, typer.Option("--format", help="Output format.")] = DeriveFormat.text,
    model: ModelOpt = None,
    no_cache: NoCacheOpt = False,
) -> None:
    """Print the closed-form Mbar, Dbar, Kbar about the trivial silent motion (eqs. 51-54, 59-61)."""
    from .numeric import cache
    from .render import render_closed_form

    if model is not None:
        from .builder import resolve_model
        from .render import render_model_closed_form

        sys.stdout.write(render_model_closed_form(resolve_model(model), fmt.value).rstrip("\n") + "\n")
        return

    text = cache.cached_text("closed-forms", f"{case.value}.{fmt.value}",
                             lambda: render_closed_form(case.value, fmt.value), use_cache=not no_cache)
    sys.stdout.write(text if text.endswith("\n") else text + "\n")


@app.command()
def linearize(
    preset: PresetOpt = None,
    params: ParamsOpt = None,
    set_: Annotated[
        Optional[list[str]], typer.Option("--set", help="Override NAME=VALUE (repeatable; VALUE may be 'inf').")
    ] = None,
    fmt: Annotated[OutFormat, typer.Option("--format", help="Output format.")] = OutFormat.text,
    model: ModelOpt = None,
    no_cache: NoCacheOpt = False,
) -> None:
    """Find the silent motion, linearize (eqs. 46-48) and print M, D, K and the eigenvalues."""
    from .analysis.linear import linearize as _linearize
    from .numeric.compiled import compiled_model
    from .parameters import parse_sets, resolve_parameters
    from .render import render_linear_model

    if model is not None:
        from .builder import linearize_model, resolve_model
        from .errors import ParameterError
        from .render import render_built_linear

        if preset or params:
            raise ParameterError("--model cannot be combined with --preset or --params (use --set for its parameters)")
        overrides = parse_sets(set_ or [])
        lm_b = linearize_model(resolve_model(model), overrides, use_cache=not no_cache)
        sys.stdout.write(render_built_linear(lm_b, fmt.value))
        return

    p = resolve_parameters(preset, params, list(set_ or []))
    lm = _linearize(p, model=compiled_model(use_cache=not no_cache))
    sys.stdout.write(render_linear_model(lm, fmt.value))


@bench_app.command("derive")
def bench_derive(
    fmt: Annotated[OutFormat, typer.Option("--format", help="Output format.")] = OutFormat.text,
    baseline: Annotated[
        bool, typer.Option("--baseline/--no-baseline", help="Also run the SymPy baseline (about a minute).")
    ] = True,
) -> None:
    """Cold derivation + symbolic linearization against a straightforward SymPy derivation."""
    from .bench import bench_derive as _bench, report

    sys.stdout.write(report(_bench(baseline=baseline), fmt.value))


def _register_plugins() -> None:
    """Add the commands that live in their own modules (analysis, simulation)."""
    import importlib

    for name in ("cli_stability", "cli_simulate", "cli_export", "cli_sweep", "cli_cache"):
        try:
            mod = importlib.import_module(f".{name}", __package__)
        except ModuleNotFoundError as exc:
            if exc.name != f"{__package__}.{name}":
                raise
            continue
        mod.register(app, bench_app)


_register_plugins()


def main(argv: list[str] | None = None) -> int:
    """Entry point: run the CLI, turning user errors into one stderr line and exit status 2."""
    try:
        rv = app(args=argv, prog_name="brakesqueal", standalone_mode=False)
    except BrakesquealError as exc:
        print(f"brakesqueal: error: {exc}", file=sys.stderr)
        return 2
    except TyperException as exc:
        if type(exc).__name__ == "NoArgsIsHelpError":
            return 0
        msg = exc.format_message().replace("\n", " ")
        print(f"brakesqueal: error: {msg}", file=sys.stderr)
        return 2
    except Exit as exc:
        return exc.exit_code
    except (Abort, KeyboardInterrupt):
        print("brakesqueal: aborted", file=sys.stderr)
        return 130
    return rv if isinstance(rv, int) else 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
