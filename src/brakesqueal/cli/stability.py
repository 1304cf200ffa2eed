"""Stability commands: ``crossings``, ``critical-speed``, ``map`` and ``reproduce``, for every model.

Registered by :mod:`brakesqueal.cli` through :func:`register`; heavy modules
(numba, xarray, matplotlib, scipy) are imported inside the commands.  The
options ``--model/--preset/--params/--set`` are resolved once by
:func:`~brakesqueal.cli._options.space_from`; output paths are checked before
anything is computed and written atomically (:mod:`brakesqueal.outputs`).
"""

from __future__ import annotations

import json
import math
import sys
from enum import Enum
from typing import TYPE_CHECKING, Annotated, Any, Optional

import typer

from ..errors import ParameterError
from ._options import (PLOT_SUFFIXES, ContactLaw, FormatOpt, ModelOpt, Modes, ModesOpt, OutFormat, PadDampingOpt,
                       PadSlopeOpt, ParamsOpt, PresetOpt, ProgressOpt, SetOpt, StickSpeedOpt, pads_option,
                       refuse_set_of_axes, space_from, with_equations)

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from ..analysis.maps import Axis
    from ..model.parameters import ParameterSpace
    from ..nonlinear.models import HopfPoint
    from ..results import CriticalSpeedResult, CrossingResult

__all__ = ["register"]


class _Color(str, Enum):
    verdict = "verdict"
    max_real = "max_real"
    frequency = "frequency"


class _Pads(str, Enum):
    auto = "auto"
    exact = "exact"
    quasi_static = "quasi-static"


class _Fig(str, Enum):
    fig2 = "fig2"
    fig3 = "fig3"
    all = "all"


_PlotOpt = Annotated[Optional[str], typer.Option("--plot", help="Also draw the result (PNG, SVG or PDF).")]
_PLOT_SUFFIXES = PLOT_SUFFIXES


def _write_plot(fig: Figure, plot: str) -> None:
    from ..outputs import atomic_write

    with atomic_write(plot, what="--plot") as tmp:
        fig.savefig(tmp, dpi=300)


_HopfOpt = Annotated[bool, typer.Option("--hopf", help="Add the Hopf normal form at every crossing (l1, "
                                         "criticality, predicted amplitude; as the hopf command).")]


def crossings(
    along: Annotated[str, typer.Option("--along", help="NAME=START:STOP[:log] path to search.")],
    model: ModelOpt = None, preset: PresetOpt = None, params: ParamsOpt = None, set_: SetOpt = None,
    fmt: FormatOpt = OutFormat.text, plot: _PlotOpt = None, hopf: _HopfOpt = False, modes: ModesOpt = Modes.all,
) -> None:
    """Every parameter value on a path where the stability of the silent motion changes (exact where possible)."""
    from ..analysis.maps import parse_axis
    from ..api import crossings as _crossings
    from ..outputs import check_output

    axis = parse_axis(along, with_num=False)
    refuse_set_of_axes(set_, {axis.name: "--along"})
    if plot:
        check_output(plot, what="--plot", suffixes=_PLOT_SUFFIXES)
    space = space_from(model, preset, params, set_, axes={axis.name: "--along"})
    r: CrossingResult = _crossings(space, axis, modes=modes.value)
    if plot:
        _write_plot(r.plot(), plot)
    _write_crossings(r, space, axis, fmt, hopf)


def _write_crossings(r: CrossingResult, space: ParameterSpace, axis: Axis, fmt: OutFormat, hopf: bool) -> None:
    """Text or JSON of a crossing result; with ``hopf`` every crossing gains its normal form (as ``hopf``)."""
    if not hopf:
        sys.stdout.write(json.dumps(r.to_dict(), indent=2) + "\n" if fmt == OutFormat.json else r.text())
        return
    from ..api_nonlinear import hopf_points

    _write_hopf_points(r, hopf_points(space, axis, result=r), fmt)


def _write_hopf_points(r: CrossingResult, pts: list[HopfPoint], fmt: OutFormat) -> None:
    """Text or JSON of a crossing result whose crossings are the Hopf points ``pts`` (their normal forms)."""
    if fmt == OutFormat.json:
        d = r.to_dict()
        d["crossings"] = [hp.to_dict() for hp in pts]
        sys.stdout.write(json.dumps(d, indent=2, default=float) + "\n")
    else:
        sys.stdout.write(r.text() + _hopf_text(pts))


def critical_speed(
    range_: Annotated[str, typer.Option("--range", help="Omega range START:STOP [rad/s], 0 < START < STOP "
                                        "(searched on a logarithmic path).")] = "1:1e5",
    model: ModelOpt = None, preset: PresetOpt = None, params: ParamsOpt = None, set_: SetOpt = None,
    fmt: FormatOpt = OutFormat.text, plot: _PlotOpt = None, hopf: _HopfOpt = False, modes: ModesOpt = Modes.all,
) -> None:
    """All onsets and re-stabilisations of squeal along the spin rate Omega, and Omega_crit."""
    from ..analysis.crossings import omega_name
    from ..analysis.maps import Axis
    from ..api import critical_speeds
    from ..outputs import check_output

    lo, hi = _omega_range(range_)
    refuse_set_of_axes(set_, {"Omega": "--range"})
    if plot:
        check_output(plot, what="--plot", suffixes=_PLOT_SUFFIXES)
    space = space_from(model, preset, params, set_)
    name = omega_name(space)
    refuse_set_of_axes(set_, {name: "--range"})
    axis = Axis(name, lo, hi, 2, True)
    r: CriticalSpeedResult = critical_speeds(space, axis.start, axis.stop, modes=modes.value)
    if plot:
        _write_plot(r.plot(), plot)
    _write_crossings(r, space, axis, fmt, hopf)


def _omega_range(text: str) -> tuple[float, float]:
    """``--range START:STOP`` of ``critical-speed``: two numbers with ``0 < START < STOP`` [rad/s], resolved."""
    from ..analysis.maps import resolution_problem
    from ..model.expressions import evaluate

    rule = "--range must be START:STOP in rad/s with 0 < START < STOP"
    parts = [p.strip() for p in text.split(":")]
    if len(parts) != 2 or not all(parts):
        raise ParameterError(f"{rule} (two numbers; the path is always logarithmic); got {text!r}",
                             parameter="--range")
    lo, hi = (evaluate(p, {}, what=f"--range {w}") for p, w in zip(parts, ("START", "STOP")))
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
        raise ParameterError(f"{rule} (both positive and finite); got {text!r}", parameter="--range")
    problem = resolution_problem(lo, hi, 2, True)
    if problem:
        raise ParameterError(f"--range: {problem}", parameter="--range")
    return lo, hi


def map_(
    x: Annotated[str, typer.Option("--x", help="NAME=START:STOP:N[:log] (horizontal axis).")],
    y: Annotated[str, typer.Option("--y", help="NAME=START:STOP:N[:log] (vertical axis).")],
    out: Annotated[str, typer.Option("--out", help="NetCDF file to write (.nc).")],
    plot: _PlotOpt = None,
    model: ModelOpt = None, preset: PresetOpt = None, params: ParamsOpt = None, set_: SetOpt = None,
    force: Annotated[bool, typer.Option("--force", help="Allow more than 1e9 points (memory stays bounded; a "
                                                        "file variable holds at most 4 GiB).")] = False,
    no_eigen: Annotated[bool, typer.Option("--no-eigen", help="Only classify: the file has stable and status, "
                                                              "no max_real or frequency.")] = False,
    progress: ProgressOpt = None,
    color: Annotated[Optional[_Color], typer.Option(
        "--color", help="What the plot's colours show: the verdict, or max Re λ or the frequency.")] = None,
    modes: ModesOpt = Modes.all,
) -> None:
    """Stability map over two parameters of any model: NetCDF (stable, status, max_real, frequency, the carrier
    mode and the deciding route of every point); optional plot."""
    from ..analysis.maps import parse_axis
    from ..api import write_map
    from ..outputs import atomic_write, check_output
    from ._progress import progress as _progress

    ax_x, ax_y = parse_axis(x), parse_axis(y)
    refuse_set_of_axes(set_, {ax_x.name: "--x", ax_y.name: "--y"})
    if color is not None and not plot:
        raise ParameterError("--color only changes the figure: give --plot FILE too")
    if color not in (None, _Color.verdict) and no_eigen:
        raise ParameterError(f"--color {color.value} needs max_real and frequency: leave out --no-eigen")
    check_output(out, what="--out", suffixes=(".nc",))
    if plot:
        check_output(plot, what="--plot", suffixes=_PLOT_SUFFIXES)
    space = space_from(model, preset, params, set_, axes={ax_x.name: "--x", ax_y.name: "--y"})
    with _progress("map", progress) as cb, atomic_write(out, what="--out") as tmp:
        s = write_map(space, ax_x, ax_y, str(tmp), force=force, eigen=not no_eigen, progress=cb, modes=modes.value)
    msg = f"wrote {out}"
    if plot:
        from ..results import plot_map_file

        _write_plot(plot_map_file(out, x=ax_x.name, color=(color or _Color.verdict).value), plot)
        msg += f" and {plot}"
    sys.stdout.write(f"{msg} ({s.text()}; {s.method})\n")


def reproduce(
    figure: Annotated[_Fig, typer.Argument(help="Which figure: fig2, fig3 or all.")],
    out: Annotated[str, typer.Option("--out", help="Output directory.")] = "results",
    progress: ProgressOpt = None,
) -> None:
    """Reproduce the paper's Figures 2 and 3 (PNG, NetCDF, CSV, JSON) into a directory."""
    from ..outputs import check_output_dir
    from ..reproduce import reproduce_fig2, reproduce_fig3
    from ._progress import progress as _progress

    check_output_dir(out, what="--out")
    summaries = []
    if figure in (_Fig.fig2, _Fig.all):
        with _progress("fig2", progress) as cb:
            s = reproduce_fig2(out, progress=cb)
        summaries.append(s)
        sys.stdout.write(f"Fig. 2: mu = {s['mu_line']}: A at k_ip = {s['A_k_ip']:.6g} N/m (unstable -> stable), "
                         f"B at k_ip = {s['B_k_ip']:.6g} N/m (stable -> unstable) while k_ip decreases\n")
    if figure in (_Fig.fig3, _Fig.all):
        with _progress("fig3", progress) as cb:
            s = reproduce_fig3(out, progress=cb)
        summaries.append(s)
        for k, c in s["curves"].items():
            sys.stdout.write(f"Fig. 3: k_ip = {k}: Omega_crit(mu1 = mu2) = {c['Omega_crit_at_equal_mu']:.6g} rad/s, "
                             f"stable throughout for |mu1 - mu2| >= {c['stable_throughout_for_abs_mu_diff_above']}\n")
    for s in summaries:
        sys.stdout.write("figures and data: " + ", ".join(s["files"]) + "\n")


def _hopf_text(points: list[HopfPoint]) -> str:
    lines = []
    for hp in points:
        h = hp.hopf
        head = f"  {hp.parameter} = {hp.value:.12g} ({hp.direction})"
        if h is None:
            lines.append(f"{head}: {hp.message}")
            continue
        amp = ", ".join(f"{n}: {a:.4g}" for n, a in list(zip(h.state_names, h.amplitude_coefficients))[:4])
        lines.append(f"{head}: Hopf at {h.frequency0_hz:.6g} Hz, {h.criticality}, "
                     f"l1 = {h.l1:.6g} ± {h.l1_error:.2g}")
        if h.side:
            lines.append(f"      cycles for {hp.parameter} {'>' if h.side > 0 else '<'} {h.p0:.12g}; first-harmonic "
                         f"amplitudes A_j ~ a_j sqrt(|{hp.parameter} - p0|), a_j = {amp}")
        for what, at, tilt in (("a pad lifts off", hp.contact_loss, hp.tilt_at_contact_loss),
                               ("a pad's sliding reverses (quasi-static pads: end of validity; often later on "
                                "the cycles)", hp.sliding_reversal, hp.tilt_at_sliding_reversal)):
            if at is not None:
                lines.append(f"      predicted (leading order): {what} at {hp.parameter} = {at:.8g}"
                             + (f", tilt amplitude {tilt:.3g} rad" if tilt is not None else ""))
        lines += [f"      warning: {w}" for w in h.warnings]
        if hp.message:
            lines.append(f"      note: {hp.message}")
    return "\n".join(lines) + "\n"


def hopf(
    along: Annotated[str, typer.Option("--along", help="NAME=START:STOP[:log] path to search.")] = "Omega=1:1e5:log",
    model: ModelOpt = None, preset: PresetOpt = None, params: ParamsOpt = None, set_: SetOpt = None,
    fmt: FormatOpt = OutFormat.text, pad_damping: PadDampingOpt = None,
) -> None:
    """Hopf criticality at every stability crossing on a path: l1, sub/supercritical, predicted cycle amplitude."""
    from ..analysis.crossings import crossings as _crossings
    from ..analysis.maps import parse_axis
    from ..codegen import build
    from ..nonlinear.models import hopf_points

    axis = parse_axis(along, with_num=False)
    refuse_set_of_axes(set_, {axis.name: "--along"})
    base = with_equations(space_from(model, preset, params, set_, axes={axis.name: "--along"}), "hopf")
    space = pads_option(base, None, None, pad_damping)
    engine = build(space.model)  # the entry point's engine, passed down
    r: CrossingResult = _crossings(engine, space, axis)
    _write_hopf_points(r, hopf_points(engine, space, axis, result=r), fmt)


def cycles(
    along: Annotated[str, typer.Option("--along", help="NAME=START:STOP[:log]: the first Hopf point in the range is "
                                       "continued within it.")],
    model: ModelOpt = None, preset: PresetOpt = None, params: ParamsOpt = None, set_: SetOpt = None,
    fmt: FormatOpt = OutFormat.text, plot: _PlotOpt = None,
    out: Annotated[Optional[str], typer.Option("--out", help="NetCDF file of the branch (.nc).")] = None,
    max_points: Annotated[int, typer.Option("--max-points", min=2, max=2000,
                                            help="Largest number of branch points.")] = 60,
    contact_: Annotated[ContactLaw, typer.Option(
        "--contact", help="bilateral: the branch is valid up to the first contact loss (located); unilateral: "
                          "continued through lift-off and re-contact (F_n = max(0, .), slower).")
    ] = ContactLaw.bilateral,
    pad_slope: PadSlopeOpt = None,
    stick_speed: StickSpeedOpt = None,
    pad_damping: PadDampingOpt = None,
    pads_: Annotated[_Pads, typer.Option(
        "--pads", help="auto: every pad's tangential rate kept, by shooting where the simulated equations keep it, "
                       "by harmonic balance where massless Coulomb pads with a finite k_ip would be quasi-static "
                       "(bilateral; with --contact unilateral choose --pad-damping D or --pads quasi-static); exact: "
                       "harmonic balance; quasi-static: shooting with ldot := 0 for those pads (exact to first order "
                       "at the onset).")] = _Pads.auto,
    exact_pads: Annotated[bool, typer.Option("--exact-pads", help="Same as --pads exact: harmonic balance on the "
                                             "implicit equations, the massless Coulomb pads exact (tangential rates "
                                             "kept, no regularisation); bilateral, to the located contact "
                                             "loss.")] = False,
    harmonics: Annotated[int, typer.Option("--harmonics", min=1, max=200, help="Harmonic-balance route (soft "
                                           "Coulomb pads by default, or --pads exact): initial number of harmonics "
                                           "(raised while the truncation error or the off-grid residual exceeds "
                                           "1e-6, or, where the pads allow shooting, the shooting "
                                           "mismatch).")] = 6,
    max_harmonics: Annotated[int, typer.Option("--max-harmonics", min=1, max=400, help="Harmonic-balance route: "
                                               "largest number of harmonics (the branch stops where more are "
                                               "needed).")] = 60,
    progress: ProgressOpt = None,
) -> None:
    """Limit cycles from the first Hopf point on a path: amplitude, frequency, stability, where a pad lifts off."""
    from ..analysis.maps import parse_axis
    from ..codegen import build
    from ..nonlinear.models import PAD_TREATMENTS, cycle_route, limit_cycles
    from ..outputs import check_output

    axis = parse_axis(along, with_num=False)
    refuse_set_of_axes(set_, {axis.name: "--along"})
    contact, pads = contact_.value, pads_.value
    if pads not in PAD_TREATMENTS:  # pragma: no cover - the choices of --pads are PAD_TREATMENTS
        raise ParameterError(f"The option '--pads' must be one of {', '.join(PAD_TREATMENTS)}; got {pads!r}")
    if exact_pads:
        if pads == "quasi-static":
            raise ParameterError("The option '--exact-pads' cannot be combined with --pads quasi-static")
        pads = "exact"
    if pads == "quasi-static" and (pad_damping is not None or pad_slope is not None):
        raise ParameterError("The option '--pads quasi-static' cannot be combined with --pad-damping or --pad-slope "
                             "(they keep the pads' rates)")
    base = with_equations(space_from(model, preset, params, set_, axes={axis.name: "--along"}), "cycles")
    space = pads_option(base, pad_slope, stick_speed, pad_damping)  # checked before anything is computed
    route = cycle_route(space, axis, contact=contact, pads=pads)
    options: dict[str, Any] = {}
    if route == "harmonic balance":
        for flag, bad in (("--contact unilateral", contact != "bilateral"), ("--pad-slope", pad_slope is not None),
                          ("--stick-speed", stick_speed is not None)):
            if bad:
                raise ParameterError(f"The option '--pads exact' (or --exact-pads) cannot be combined with {flag} "
                                     "(the exact pads are bilateral and unregularised)")
        if max_harmonics < harmonics:
            raise ParameterError(f"The option '--max-harmonics' must be >= --harmonics = {harmonics}; got "
                                 f"{max_harmonics}")
        options = {"harmonics": harmonics, "max_harmonics": max_harmonics}
    if plot:
        check_output(plot, what="--plot", suffixes=_PLOT_SUFFIXES)
    if out:
        check_output(out, what="--out", suffixes=(".nc",))
    from ._progress import progress as _progress

    engine = build(space.model)  # the entry point's engine, passed down
    title = "cycles (harmonic balance)" if route == "harmonic balance" else "cycles"
    with _progress(title, progress) as cb:
        b = limit_cycles(engine, space, axis, contact=contact, pads=pads, max_points=max_points, progress=cb,
                         **options)
    if b.to_dict()["route"] == "harmonic balance":  # the route that ran (shooting may fall back to it)
        _write_harmonic(b, axis, fmt=fmt, plot=plot, out=out)
    else:
        _write_shooting(b, axis, fmt=fmt, plot=plot, out=out)


def _write_branch_data(ds: Any, out: str) -> None:
    """The branch's Dataset as NetCDF (``--out``; strings as bytes for the scipy engine), written atomically."""
    from ..outputs import atomic_write

    ds = ds.assign_coords(coord=ds["coord"].astype("S"), pad=ds["pad"].astype("S"))
    with atomic_write(out, what="--out") as tmp:
        ds.to_netcdf(str(tmp), engine="scipy")


def _write_shooting(b: Any, axis: Any, *, fmt: OutFormat, plot: str | None, out: str | None) -> None:
    """``cycles`` by shooting: text or JSON, ``--out`` NetCDF, ``--plot`` bifurcation diagram."""
    if out:
        ds = b.data.copy()
        ds.attrs = {k: (json.dumps(v) if isinstance(v, (dict, list, tuple)) or v is None else v)
                    for k, v in ds.attrs.items()}
        for k in ("label", "special_kind", "special_description", "verdict"):
            if k in ds:
                ds[k] = ds[k].astype("S")
        _write_branch_data(ds, out)
    if plot:
        _write_plot(b.plot(), plot)
    d = b.to_dict()
    if fmt == OutFormat.json:
        sys.stdout.write(json.dumps(d, indent=2, default=float) + "\n")
        return
    h = b.hopf.branch_start
    assert h is not None
    lines = [f"Hopf point {axis.name} = {h.p0:.12g}: {h.criticality} (l1 = {h.l1:.6g} ± {h.l1_error:.2g}), "
             f"{h.frequency0_hz:.6g} Hz" + (" in the simulated equations (quasi-static pads)"
                                            if b.hopf.simulated is not None else ""),
             f"{d['points']} branch points ({d['status']}: {d['message']})"]
    if b.contact_loss is not None and b.contact == "bilateral":
        amp = ", ".join(f"{k}: {v:.4g}" for k, v in list(d["amplitude_at_last_contact_point"].items())[:2])
        lines.append(f"a pad loses contact at {axis.name} = {b.contact_loss:.8g} (first-harmonic amplitude {amp} "
                     f"at {d['in_contact_up_to']:.8g}; the bilateral equations do not hold beyond; "
                     "--contact unilateral continues)")
    elif b.contact_loss is None:
        lines.append("the pads stay in contact along the whole branch")
    lines += [f"special point {sp['kind']} at {axis.name} = {sp['p']:.10g}" for sp in d["special_points"]
              if sp["kind"] != "H"]
    if b.hopf.message:
        lines.append(f"note: {b.hopf.message}")
    lines += _floquet_lines(d.get("floquet", []), axis.name)
    summary = b.summary.text() if b.summary is not None else ""
    sys.stdout.write("\n".join(lines) + "\n" + summary)


def _floquet_lines(rows: list[dict[str, Any]], name: str) -> list[str]:
    """The shooting route's verified Floquet data in a few lines: the trivial multiplier, the verdicts, the
    undecided points."""
    if not rows:
        return []
    cyc = [r for r in rows if r["label"] != "H"]  # the Hopf row has no cycle: its multipliers are predicted
    worst = max((r["trivial_multiplier_error"] for r in cyc), default=float("nan"))
    counts = {v: sum(r["verdict"] == v for r in cyc) for v in ("stable", "unstable", "undecided")}
    out = [f"Floquet multipliers (monodromy): the trivial multiplier within {worst:.2g} of 1 on every cycle; "
           f"{counts['stable']} stable, {counts['unstable']} unstable, {counts['undecided']} undecided (a "
           "non-trivial |multiplier| within the accuracy bound of 1)"]
    for r in cyc:
        if r["verdict"] == "undecided":
            out.append(f"  undecided at {name} = {r['p']:.10g}{' (' + r['label'] + ')' if r['label'] else ''}: "
                       f"largest |multiplier| {r['largest_multiplier']:.12g}, accuracy "
                       f"{r['multiplier_accuracy']:.2g}")
    return out


def _write_harmonic(b: Any, axis: Any, *, fmt: OutFormat, plot: str | None, out: str | None) -> None:
    """``cycles`` by harmonic balance (exact pads): text or JSON, ``--out`` NetCDF, ``--plot`` bifurcation
    diagram."""
    if out:
        ds = b.data
        _write_branch_data(ds.assign(verdict=ds["verdict"].astype("S")), out)
    if plot:
        _write_plot(b.plot(), plot)
    if fmt == OutFormat.json:
        sys.stdout.write(json.dumps(b.to_dict(), indent=2, default=float) + "\n")
        return
    from ..labels import branch_status_text

    h = b.hopf.hopf
    lines = [f"Hopf point {axis.name} = {h.p0:.12g}: {h.criticality} (l1 = {h.l1:.6g} ± {h.l1_error:.2g}), "
             f"{h.frequency0_hz:.6g} Hz (exact pads: tangential rates kept)",
             f"{len(b.points)} branch points by harmonic balance ({branch_status_text(b.status)}: {b.message})",
             f"stability: {b.stability}" + (", cross-checked with the monodromy of the simulated equations"
                                             if any(pt.monodromy_verdict is not None for pt in b.points) else "")]
    terr = [pt.trivial_multiplier_error for pt in b.points if pt.trivial_multiplier_error is not None]
    if terr:
        counts = {v: sum(pt.verdict == v for pt in b.points) for v in ("stable", "unstable", "undecided")}
        lines.append(f"Floquet multipliers (Hill's method): the trivial multiplier within {max(terr):.2g} of 1 on "
                     f"every cycle; {counts['stable']} stable, {counts['unstable']} unstable, "
                     f"{counts['undecided']} undecided; harmonics {min(pt.harmonics for pt in b.points)}.."
                     f"{max(pt.harmonics for pt in b.points)}, residual up to "
                     f"{max(pt.residual for pt in b.points):.2g}")
    lines += b.summary.text(rows=0).splitlines()
    # the normal forces' range over the period: min (a pad lifts off where it reaches 0) and max (as the
    # unilateral table of the summary)
    head = (f"{axis.name:>12} {'f [Hz]':>10} {'tilt [rad]':>11} "
            + " ".join(f"{'Fn min ' + p:>10} {'Fn max ' + p:>10}" for p in b.pads)
            + f" {'slide min':>10} {'H':>3} {'trunc':>8} {'resid':>8} {'|mu0-1|':>8} {'shoot':>8}  stable")
    lines.append(head)
    for pt, ok in zip(b.points, b.valid):
        tilt = f"{pt.tilt_amplitude:11.4g}" if pt.tilt_amplitude is not None else f"{'-':>11}"
        st = "-" if pt.stable is None else ("yes" if pt.stable else "no")
        if pt.verdict == "undecided" and (pt.hill_verdict is not None or pt.monodromy_verdict is not None):
            st = (f"undecided (Hill: {pt.hill_verdict or '-'}, monodromy: {pt.monodromy_verdict})"
                  if pt.monodromy_verdict is not None else "undecided")
        if not ok:  # past a contact loss the bilateral equations do not hold (the figure greys these orbits)
            st = "not valid (contact lost)"
        fmax = [f"{v:10.5g}" for v in pt.F_n_max] if len(pt.F_n_max) == len(pt.F_n_min) else [f"{'-':>10}"] * len(
            pt.F_n_min)
        lines.append(f"{pt.p:12.8g} {pt.frequency_hz:10.6g} {tilt} "
                     + " ".join(f"{lo:10.5g} {hi}" for lo, hi in zip(pt.F_n_min, fmax))
                     + f" {pt.sliding_margin_min:10.4g} {pt.harmonics:3d} {pt.truncation_error:8.1e} "
                       f"{pt.residual:8.1e} {_e8(pt.trivial_multiplier_error)} {_e8(pt.shooting_mismatch)}  {st}")
    sys.stdout.write("\n".join(lines) + "\n")


def _e8(v: float | None) -> str:
    return f"{'-':>8}" if v is None else f"{v:8.1e}"


def register(app: typer.Typer) -> None:
    """Add the stability commands to ``app``.

    Parameters
    ----------
    app : typer.Typer
        The main application.
    """
    app.command("crossings")(crossings)
    app.command("critical-speed")(critical_speed)
    app.command("hopf")(hopf)
    app.command("cycles")(cycles)
    app.command("map")(map_)
    app.command("reproduce")(reproduce)
