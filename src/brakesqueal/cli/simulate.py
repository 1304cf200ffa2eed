"""``brakesqueal simulate`` (registered by :mod:`brakesqueal.cli`).

Heavy modules (numba, SciPy, the kernels) are imported inside the commands.
"""

from __future__ import annotations

import json
import math
import sys
from enum import Enum
from typing import TYPE_CHECKING, Annotated, Any, Optional, cast

import typer

from ..errors import ParameterError
from ._options import (NUMBER, PLOT_SUFFIXES, ContactLaw, ModelOpt, OutFormat, PadDampingOpt, PadSlopeOpt, ParamsOpt,
                       PresetOpt, SetOpt, StickSpeedOpt, pads_option, space_from,
                       with_equations)

if TYPE_CHECKING:
    from ..model.parameters import Parameters
    from ..simulation import EventMode
    from ..simulation.trajectory import Trajectory

__all__ = ["register"]


class _Events(str, Enum):
    """``--events``: what a contact loss or sliding reversal does to the run."""

    stop = "stop"
    continue_ = "continue"
    off = "off"


def _floats(text: str, what: str) -> list[float]:
    try:
        vals = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise ParameterError(f"The option '{what}' must be comma-separated numbers; got {text!r}") from None
    if not all(math.isfinite(v) for v in vals):
        raise ParameterError(f"The option '{what}' must be finite; got {text!r}")
    return vals


_NETCDF_SUFFIXES = (".nc", ".nc4", ".cdf", ".netcdf")


def _check_outputs(out: str | None, plot: str | None, wav: str | None) -> None:
    """Every output path is checked before anything is computed (one line, exit status 2)."""
    from pathlib import Path

    from ..outputs import check_output

    given = {opt: path for opt, path in (("--out", out), ("--plot", plot), ("--wav", wav)) if path}
    if out:
        check_output(out, what="--out", suffixes=_NETCDF_SUFFIXES)
    if wav:
        check_output(wav, what="--wav", suffixes=(".wav",))
    if plot:
        check_output(plot, what="--plot", suffixes=PLOT_SUFFIXES)
    seen: dict[Path, str] = {}
    for opt, path in given.items():
        key = Path(path).resolve()
        if key in seen:
            raise ParameterError(f"the options {seen[key]} and {opt} name the same file '{path}'")
        seen[key] = opt


def _simulate_cmd(
    model: ModelOpt = None, preset: PresetOpt = None, params: ParamsOpt = None, set_: SetOpt = None,
    t_end: Annotated[float, typer.Option("--t-end", **NUMBER, help="Simulated time [s].")] = 0.5,
    q0: Annotated[
        Optional[str],
        typer.Option(
            "--q0",
            help="Initial deviation from the silent motion: one value per coordinate, optionally followed by "
            "their rates (paper: dq1,dq2[,dq1dot,dq2dot] [rad, rad/s]; default: along the leading mode, 1e-5).",
        ),
    ] = None,
    x0: Annotated[
        Optional[str], typer.Option("--x0", help="Absolute initial state: coordinates and rates (instead of --q0).")
    ] = None,
    method: Annotated[str, typer.Option("--method", help="DOP853-jit (default) or a solve_ivp method.")] = "DOP853-jit",
    rtol: Annotated[float, typer.Option("--rtol", **NUMBER, help="Relative tolerance, in [1e-13, 1e-2].")] = 1e-9,
    atol: Annotated[Optional[float], typer.Option(
        "--atol", **NUMBER, help="Absolute tolerance (default from rtol).")] = None,
    events: Annotated[_Events, typer.Option(
        "--events", help="At a contact loss or sliding reversal: stop, continue (record it) or off.")] = _Events.stop,
    contact: Annotated[ContactLaw, typer.Option(
        "--contact", help="bilateral (pads stay pressed) or unilateral (F_n = max(0, .): pads lift off and come "
                          "back; DOP853-jit only).")] = ContactLaw.bilateral,
    pad_slope: PadSlopeOpt = None,
    stick_speed: StickSpeedOpt = None,
    pad_damping: PadDampingOpt = None,
    sample_rate: Annotated[float, typer.Option(
        "--sample-rate", **NUMBER, help="Output samples per second [Hz].")] = 44100.0,
    out: Annotated[Optional[str], typer.Option("--out", help="Write the trajectory to this NetCDF file.")] = None,
    plot: Annotated[Optional[str], typer.Option(
        "--plot", help="Write the plot: time history, phase, spectrum (PNG, SVG or PDF).")] = None,
    wav: Annotated[
        Optional[str],
        typer.Option("--wav", help="Write the rim's normal velocity (a belt: the pad's) as 44.1 kHz audio."),
    ] = None,
    fmt: Annotated[OutFormat, typer.Option("--format", help="Summary format.")] = OutFormat.text,
    progress: Annotated[bool, typer.Option(
        "--progress/--no-progress",
        help="Progress on stderr: a bar on a terminal, a line every 10 s otherwise.")] = True,
    no_cache: Annotated[bool, typer.Option("--no-cache", help="Do not read or write the cache.")] = False,
) -> None:
    """Integrate the nonlinear equations (44) of any model from a perturbed silent motion; write NetCDF, plot, audio.

    Every output path is checked first; files are written atomically (an
    interrupted or failed write keeps an existing file).  Ctrl-C stops within
    about 0.1 s, during a first compilation within about 0.5 s (exit status 130).
    A span the model's stiffness makes infeasible for the explicit integrator
    (more than 1e8 steps, e.g. --set d_t=1e50) is refused before it starts,
    with the estimate.
    """
    if not (math.isfinite(t_end) and t_end > 0):
        raise ParameterError(f"The option '--t-end' must be a positive number of seconds; got {t_end!r}")
    if q0 is not None and x0 is not None:
        raise ParameterError("give either --q0 (deviation from the silent motion) or --x0 (absolute state), not both")
    init: dict[str, Any] = {}
    if x0 is not None:
        init["x0"] = _floats(x0, "--x0")
    elif q0 is not None:
        init["perturbation"] = _floats(q0, "--q0")
    _check_outputs(out, plot, wav)
    from ..interrupts import interrupt_guard
    p = pads_option(with_equations(space_from(model, preset, params, set_), "simulate"), pad_slope, stick_speed,
                    pad_damping).resolve({})
    with interrupt_guard():  # nested in the program's guard (brakesqueal.cli.main), which ends a stuck run
        tr = _run(p, t_end, method, rtol, atol, events.value, sample_rate, progress, no_cache,
                  {**init, "contact": contact.value})
        if wav and tr.t.size < 2:
            raise ParameterError("the trajectory has fewer than two samples; nothing to write to --wav")
        wav_s = _write(tr, out, plot, wav)
    summary = tr.summary
    from ..model.components import coordinate_unit

    data = {**summary.to_dict(), "model": tr.model, "message": tr.message, "start": tr.start,
            "t_end_reached": tr.t_end_reached, "duration_s": tr.duration, "stop_reason": tr.stop_reason,
            "amplitude_final_unit": _norm_unit(tr.coords),
            "amplitude_final_by_coordinate": {c: {"amplitude": a if math.isfinite(a) else None,
                                                  "unit": coordinate_unit(c)}
                                              for c, a in tr.final_amplitudes().items()},
            "wall_s": tr.stats.get("wall_s")}  # fmt: skip
    if wav_s is not None:
        data["wav_s"] = wav_s
    if contact == ContactLaw.unilateral:
        data["contact"] = contact.value
        duty = tr.duty_cycle
        data["duty_cycle"] = None if duty is None else {str(k): float(v) for k, v in zip(tr.pads, duty)}
    if fmt == OutFormat.json:
        sys.stdout.write(json.dumps(data, indent=2) + "\n")
    else:
        for k, v in data.items():
            sys.stdout.write(f"{k:22s} {v}\n")
    for w in summary.warnings:
        sys.stderr.write(f"brakesqueal: warning: {w}\n")
    if tr.status != "finished" or wav_s is not None:
        # why the run (and with it the WAV) is as long as it is: never a short file without a reason
        note = f"the run {tr.stop_reason}"
        if wav_s is not None:
            note += f"; {wav} holds {wav_s:.4g} s of audio"
        sys.stderr.write(f"brakesqueal: note: {note}\n")
    if tr.status == "failed":
        # outputs are written; exit status 1 distinguishes a solver failure from bad input (2)
        sys.stderr.write(f"brakesqueal: simulation failed: {tr.message}\n")
        raise SystemExit(1)


def _norm_unit(coords: tuple[str, ...] | list[str]) -> str:
    """The unit of ``amplitude_final`` (a norm over every coordinate): one unit, or why there is none."""
    from ..model.components import coordinate_unit

    units = sorted({coordinate_unit(c) for c in coords})
    if len(units) == 1:
        return units[0]
    return f"none (a norm over {' and '.join(units)}: see amplitude_final_by_coordinate)"


def _run(p: Parameters, t_end: float, method: str, rtol: float, atol: float | None, events: str, sample_rate: float,
         progress: bool, no_cache: bool, init: dict[str, Any]) -> Trajectory:
    from ..codegen import build
    from ..interrupts import check_interrupt
    from ..simulation import simulate, simulation_model

    sim = simulation_model(build(p.model, use_cache=not no_cache), use_cache=not no_cache)  # the entry point's engine
    check_interrupt()
    from ._progress import progress as _progress

    with _progress("simulate", None if progress else False) as cb:
        return simulate(
            sim, p, t_end, method=method, rtol=rtol, atol=atol, events=cast("EventMode", events),  # an _Events value
            sample_rate=sample_rate, progress=cb if progress else None, **init,
        )  # fmt: skip


def _write(tr: Trajectory, out: str | None, plot: str | None, wav: str | None) -> float | None:
    """Write the outputs atomically (each OSError: one line naming the option); the WAV's length [s] or None."""
    from ..interrupts import check_interrupt

    if out:
        tr.to_netcdf(out, what="--out")
        check_interrupt()
    if plot:
        from ..outputs import write_with

        fig = tr.plot()  # an Agg figure of its own, never managed by pyplot
        write_with(plot, lambda tmp: fig.savefig(tmp, dpi=300), what="--plot")
        check_interrupt()
    if wav:
        rate = 44100
        return tr.to_wav(wav, rate=rate, what="--wav") / rate
    return None


def register(app: typer.Typer) -> None:
    """Add ``simulate`` to ``app``."""
    app.command("simulate")(_simulate_cmd)
