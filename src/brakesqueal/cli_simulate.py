"""``brakesqueal simulate`` and ``brakesqueal bench simulate`` (registered by :mod:`brakesqueal.cli`).

Heavy modules (numba, SciPy, the kernels) are imported inside the commands.
"""

from __future__ import annotations

import json
import math
import sys
from typing import Annotated, Any, Optional

import typer

from .errors import ParameterError

__all__ = ["register"]


def _floats(text: str, what: str) -> list[float]:
    try:
        vals = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise ParameterError(f"The option '{what}' must be comma-separated numbers; got {text!r}") from None
    if not all(math.isfinite(v) for v in vals):
        raise ParameterError(f"The option '{what}' must be finite; got {text!r}")
    return vals


def _simulate_cmd(
    preset: Annotated[Optional[str], typer.Option("--preset", help="Named parameter template (default paper-fig2).")] = None,
    params: Annotated[Optional[str], typer.Option("--params", help="TOML parameter file.")] = None,
    set_: Annotated[
        Optional[list[str]], typer.Option("--set", help="Override NAME=VALUE (repeatable; VALUE may be 'inf').")
    ] = None,
    t_end: Annotated[float, typer.Option("--t-end", help="Simulated time [s].")] = 0.5,
    q0: Annotated[
        Optional[str],
        typer.Option(
            "--q0",
            help="Initial deviation from the silent motion: dq1,dq2[,dq1dot,dq2dot] [rad, rad/s] "
            "(default: along the leading mode, 1e-5 rad).",
        ),
    ] = None,
    x0: Annotated[
        Optional[str], typer.Option("--x0", help="Absolute initial state q1,q2,dq1,dq2 (instead of --q0).")
    ] = None,
    method: Annotated[str, typer.Option("--method", help="DOP853-jit (default) or a solve_ivp method.")] = "DOP853-jit",
    rtol: Annotated[float, typer.Option("--rtol", help="Relative tolerance, in [1e-13, 1e-2].")] = 1e-9,
    atol: Annotated[Optional[float], typer.Option("--atol", help="Absolute tolerance (default scaled from rtol).")] = None,
    events: Annotated[str, typer.Option("--events", help="stop | continue | off (contact loss, sliding reversal).")] = "stop",
    sample_rate: Annotated[float, typer.Option("--sample-rate", help="Output samples per second [Hz].")] = 44100.0,
    out: Annotated[Optional[str], typer.Option("--out", help="Write the trajectory to this NetCDF file.")] = None,
    plot: Annotated[Optional[str], typer.Option("--plot", help="Write the plot (time history, phase, spectrum).")] = None,
    wav: Annotated[Optional[str], typer.Option("--wav", help="Write the rim's normal velocity as 44.1 kHz audio.")] = None,
    fmt: Annotated[str, typer.Option("--format", help="Summary format: text | json.")] = "text",
    progress: Annotated[bool, typer.Option("--progress/--no-progress", help="Show a progress bar on stderr.")] = True,
    no_cache: Annotated[bool, typer.Option("--no-cache", help="Do not read or write the cache.")] = False,
    model: Annotated[
        Optional[str], typer.Option("--model", help="Model TOML file or built-in model (generic solve_ivp path).")
    ] = None,
) -> None:
    """Integrate the nonlinear equations (44) from a perturbed silent motion; write NetCDF, plot, audio."""
    if fmt not in ("text", "json"):
        raise ParameterError(f"The option '--format' must be text or json; got {fmt!r}")
    if not (math.isfinite(t_end) and t_end > 0):
        raise ParameterError(f"The option '--t-end' must be a positive number of seconds; got {t_end!r}")
    if q0 is not None and x0 is not None:
        raise ParameterError("give either --q0 (deviation from the silent motion) or --x0 (absolute state), not both")
    if model is not None:
        _simulate_built(model, preset, params, set_, t_end, q0 if q0 is not None else "1e-5", x0, method, rtol, out,
                        plot, wav, fmt)  # fmt: skip
        return
    from .parameters import resolve_parameters

    p = resolve_parameters(preset, params, list(set_ or []))
    init: dict[str, Any] = {}
    if x0 is not None:
        init["x0"] = _floats(x0, "--x0")
    elif q0 is not None:
        init["perturbation"] = _floats(q0, "--q0")
    from .simulation import default_model, simulate

    model = default_model(use_cache=not no_cache)
    bar = _progress_bar() if progress and sys.stderr.isatty() else None
    try:
        tr = simulate(
            model, p, t_end, method=method, rtol=rtol, atol=atol, events=events,  # type: ignore[arg-type]
            sample_rate=sample_rate, progress=bar.update if bar else None, **init,
        )  # fmt: skip
    finally:
        if bar:
            bar.close()
    if out:
        tr.to_netcdf(out)
    if plot:
        import matplotlib

        matplotlib.use("Agg")
        fig = tr.plot()
        fig.savefig(plot, dpi=120)
    if wav:
        if tr.t.size < 2:
            raise ParameterError("the trajectory has fewer than two samples; nothing to write to --wav")
        tr.to_wav(wav)
    summary = tr.summary
    data = {**summary.to_dict(), "message": tr.message, "start": tr.start,
            "t_end_reached": float(tr.t[-1]) if tr.t.size else 0.0, "wall_s": tr.stats.get("wall_s")}  # fmt: skip
    if fmt == "json":
        sys.stdout.write(json.dumps(data, indent=2) + "\n")
    else:
        for k, v in data.items():
            sys.stdout.write(f"{k:22s} {v}\n")
    for w in summary.warnings:
        sys.stderr.write(f"brakesqueal: warning: {w}\n")
    if tr.status == "failed":
        # outputs are written; exit status 1 distinguishes a solver failure from bad input (2)
        sys.stderr.write(f"brakesqueal: simulation failed: {tr.message}\n")
        raise SystemExit(1)


def _simulate_built(model: str, preset: Any, params: Any, set_: Any, t_end: float, q0: str, x0: Any,
                    method: str, rtol: float, out: Any, plot: Any, wav: Any, fmt: str) -> None:
    """``simulate --model``: the generic built-model integrator (``builder.simulate``)."""
    from .builder import resolve_model
    from .builder.simulate import simulate_model
    from .parameters import parse_sets

    if preset or params or x0 is not None or wav:
        raise ParameterError("--model cannot be combined with --preset, --params, --x0 or --wav")
    sim_method = "DOP853" if method == "DOP853-jit" else method
    tr = simulate_model(resolve_model(model), parse_sets(set_ or []), t_end,
                        _floats(q0, "--q0"), method=sim_method, rtol=rtol)  # fmt: skip
    if out:
        tr.to_netcdf(out)
    if plot:
        import matplotlib

        matplotlib.use("Agg")
        tr.plot().savefig(plot, dpi=120)
    summary = tr.summary
    data = {**summary.to_dict(), "message": tr.message}
    if fmt == "json":
        sys.stdout.write(json.dumps(data, indent=2) + "\n")
    else:
        sys.stdout.write("".join(f"{k:22s} {v}\n" for k, v in data.items()))
    for w in summary.warnings:
        sys.stderr.write(f"brakesqueal: warning: {w}\n")
    if tr.status == "failed":
        sys.stderr.write(f"brakesqueal: simulation failed: {tr.message}\n")
        raise SystemExit(1)


class _Bar:
    def __init__(self) -> None:
        self.last = -1

    def update(self, frac: float) -> None:
        pct = int(100 * frac)
        if pct != self.last:
            self.last = pct
            n = pct // 4
            sys.stderr.write(f"\rsimulating [{'#' * n}{'.' * (25 - n)}] {pct:3d}%")
            sys.stderr.flush()

    def close(self) -> None:
        sys.stderr.write("\n")


def _progress_bar() -> _Bar:
    return _Bar()


def _bench_cmd(
    fmt: Annotated[str, typer.Option("--format", help="Output format: text | json.")] = "text",
    baseline_t: Annotated[
        float, typer.Option("--baseline-t", help="Simulated time of the (slow) lambdify baseline run [s].")
    ] = 0.002,
) -> None:
    """1 s of simulated squeal (paper-fig2) vs. sympy lambdify + solve_ivp RK45 at the same tolerances."""
    from .bench import report
    from .simulation.bench import bench_simulate

    sys.stdout.write(report(bench_simulate(baseline_t=baseline_t), fmt))


def register(app: typer.Typer, bench_app: typer.Typer) -> None:
    """Add ``simulate`` to ``app`` and ``simulate`` to ``bench_app``."""
    app.command("simulate")(_simulate_cmd)
    bench_app.command("simulate")(_bench_cmd)
