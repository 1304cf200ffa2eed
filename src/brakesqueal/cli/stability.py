"""Stability commands: ``crossings``, ``critical-speed``, ``map``, ``reproduce`` and their benchmarks.

Registered by :mod:`brakesqueal.cli` through :func:`register`; heavy modules
(numba, xarray, matplotlib, scipy) are imported inside the commands.
"""

from __future__ import annotations

import json
import sys
from enum import Enum
from typing import Annotated, Optional

import typer

from ..errors import ParameterError

__all__ = ["register"]


class _Fmt(str, Enum):
    text = "text"
    json = "json"


class _Fig(str, Enum):
    fig2 = "fig2"
    fig3 = "fig3"
    all = "all"


_Preset = Annotated[Optional[str], typer.Option("--preset", help="Named parameter template (default paper-fig2).")]
_Params = Annotated[Optional[str], typer.Option("--params", help="TOML parameter file.")]
_Set = Annotated[Optional[list[str]], typer.Option("--set", help="Override NAME=VALUE (repeatable).")]
_Format = Annotated[_Fmt, typer.Option("--format", help="Output format.")]
_Model = Annotated[Optional[str], typer.Option("--model", help="Model TOML file or built-in model name.")]


def _model_space(model: str, preset: Optional[str], params: Optional[str], sets: Optional[list[str]]):  # type: ignore[no-untyped-def]
    """A built model with ``--set`` overrides (``--preset``/``--params`` do not apply to built models)."""
    from ..builder import resolve_model
    from ..builder.analysis import ModelSpace
    from ..parameters import parse_sets

    if preset or params:
        raise ParameterError("--model cannot be combined with --preset or --params (use --set for its parameters)")
    return ModelSpace(resolve_model(model), parse_sets(sets or []))


def _space(preset: Optional[str], params: Optional[str], sets: Optional[list[str]]):  # type: ignore[no-untyped-def]
    from ..analysis.space import ParameterSpace

    return ParameterSpace.from_options(preset, params, list(sets or []))


def _progress(label: str):  # type: ignore[no-untyped-def]
    """A progress callback (fraction in [0, 1]) drawing a bar on stderr."""
    def cb(frac: float) -> None:
        n = int(30 * frac)
        sys.stderr.write(f"\r{label:<8} [{'#' * n}{'.' * (30 - n)}] {100 * frac:5.1f}%")
        if frac >= 1.0:
            sys.stderr.write("\n")
        sys.stderr.flush()

    return cb


def crossings(
    along: Annotated[str, typer.Option("--along", help="NAME=START:STOP[:log] path to search.")],
    preset: _Preset = None, params: _Params = None, set_: _Set = None, fmt: _Format = _Fmt.text,
    model: _Model = None,
) -> None:
    """Every parameter value on a path where the stability of the silent motion changes (exact)."""
    from ..analysis.crossings import crossings as _crossings
    from ..analysis.maps import parse_axis

    axis = parse_axis(along, with_num=False)
    if model is not None:
        from ..builder.analysis import model_crossings

        r = model_crossings(_model_space(model, preset, params, set_), axis)
    else:
        r = _crossings(_space(preset, params, set_), axis)
    sys.stdout.write(json.dumps(r.to_dict(), indent=2) + "\n" if fmt == _Fmt.json else r.text())


def critical_speed(
    range_: Annotated[str, typer.Option("--range", help="Omega range LO:HI [rad/s].")] = "1:1e5",
    preset: _Preset = None, params: _Params = None, set_: _Set = None, fmt: _Format = _Fmt.text,
    model: _Model = None,
) -> None:
    """All onsets and re-stabilisations of squeal along the spin rate Omega, and Omega_crit."""
    from ..analysis.crossings import critical_speeds
    from ..analysis.maps import parse_axis

    axis = parse_axis(f"Omega={range_}:log", with_num=False)
    if model is not None:
        from ..builder.analysis import model_critical_speeds

        r = model_critical_speeds(_model_space(model, preset, params, set_), axis.start, axis.stop)
    else:
        r = critical_speeds(_space(preset, params, set_), axis.start, axis.stop)
    sys.stdout.write(json.dumps(r.to_dict(), indent=2) + "\n" if fmt == _Fmt.json else r.text())


def map_(
    x: Annotated[str, typer.Option("--x", help="NAME=START:STOP:N[:log] (horizontal axis).")],
    y: Annotated[str, typer.Option("--y", help="NAME=START:STOP:N[:log] (vertical axis).")],
    out: Annotated[str, typer.Option("--out", help="NetCDF file to write (.nc).")],
    plot: Annotated[Optional[str], typer.Option("--plot", help="Also draw the map (PNG/SVG/PDF).")] = None,
    preset: _Preset = None, params: _Params = None, set_: _Set = None,
    force: Annotated[bool, typer.Option("--force", help="Allow more than 1e9 points.")] = False,
    no_eigen: Annotated[bool, typer.Option("--no-eigen", help="Only classify (max_real, frequency = NaN).")] = False,
    model: _Model = None,
) -> None:
    """Stability map over two parameters: NetCDF with max_real, stable, frequency, status; optional plot."""
    from ..analysis.maps import parse_axis, stability_map
    from ..plotting import save

    ax_x, ax_y = parse_axis(x), parse_axis(y)
    if not out.endswith(".nc"):
        raise ParameterError(f"--out must name a NetCDF file ending in .nc; got {out!r}")
    prog = _progress("map") if sys.stderr.isatty() else None
    if model is not None:
        from ..builder.analysis import model_stability_map

        if ax_x.num * ax_y.num > 1e9 and not force:
            raise ParameterError(f"the map has {ax_x.num * ax_y.num:.3g} points (> 1e9); add --force to run it")
        m = model_stability_map(_model_space(model, preset, params, set_), ax_x, ax_y, eigen=not no_eigen,
                                progress=prog)
    else:
        m = stability_map(_space(preset, params, set_), ax_x, ax_y, force=force, eigen=not no_eigen, progress=prog)
    m.to_netcdf(out)
    msg = f"wrote {out}"
    if plot:
        save(m.plot(x=ax_x.name), plot)
        msg += f" and {plot}"
    st = m.data["stable"].values
    sys.stdout.write(f"{msg} ({st.size} points, {100 * st.mean():.1f}% stable)\n")


def reproduce(
    figure: Annotated[_Fig, typer.Argument(help="Which figure: fig2, fig3 or all.")],
    out: Annotated[str, typer.Option("--out", help="Output directory.")] = "results",
) -> None:
    """Reproduce the paper's Figures 2 and 3 (PNG, NetCDF, CSV, JSON) into a directory."""
    from ..reproduce import reproduce_fig2, reproduce_fig3

    summaries = []
    if figure in (_Fig.fig2, _Fig.all):
        s = reproduce_fig2(out, progress=_progress("fig2"))
        summaries.append(s)
        sys.stdout.write(f"Fig. 2: mu = {s['mu_line']}: A at k_ip = {s['A_k_ip']:.6g} N/m (unstable -> stable), "
                         f"B at k_ip = {s['B_k_ip']:.6g} N/m (stable -> unstable) while k_ip decreases\n")
    if figure in (_Fig.fig3, _Fig.all):
        s = reproduce_fig3(out, progress=_progress("fig3"))
        summaries.append(s)
        for k, c in s["curves"].items():
            sys.stdout.write(f"Fig. 3: k_ip = {k}: Omega_crit(mu1 = mu2) = {c['Omega_crit_at_equal_mu']:.6g} rad/s, "
                             f"stable throughout for |mu1 - mu2| >= {c['stable_throughout_for_abs_mu_diff_above']}\n")
    for s in summaries:
        sys.stdout.write("figures and data: " + ", ".join(s["files"]) + "\n")


def bench_map(
    fmt: _Format = _Fmt.text,
    size: Annotated[int, typer.Option("--size", help="Grid size N for the N x N kernel run.")] = 4000,
    large: Annotated[bool, typer.Option("--large", help="Also run a chunked 1e8-point map and report memory.")] = False,
) -> None:
    """Stability-map throughput: compiled kernel, NumPy path, Dataset path vs naive scipy eigvals loop."""
    from ..analysis._bench import bench_map as _b
    from ..bench import report

    sys.stdout.write(report(_b(size=size, large=large), fmt.value))


def bench_critical_speed(
    fmt: _Format = _Fmt.text,
    n: Annotated[int, typer.Option("--n", help="Number of parameter sets.")] = 100000,
) -> None:
    """Critical speeds per second (all crossings) vs numeric scan + brentq."""
    from ..analysis._bench import bench_critical_speed as _b
    from ..bench import report

    sys.stdout.write(report(_b(n=n), fmt.value))


def bench_model_map(
    fmt: _Format = _Fmt.text,
    model: Annotated[str, typer.Option("--model", help="Built-in model to map.")] = "eight-dof",
    size: Annotated[int, typer.Option("--size", help="Grid size N for the N x N map.")] = 1000,
) -> None:
    """Built-model map throughput (Routh classification, eigenvalue path) vs batched numpy.linalg.eigvals."""
    from ..bench import report
    from ..builder.analysis import bench_model_map as _b

    sys.stdout.write(report(_b(model, size), fmt.value))


def register(app: typer.Typer, bench_app: typer.Typer) -> None:
    """Add the stability commands to ``app`` and their benchmarks to ``bench_app``."""
    app.command("crossings")(crossings)
    app.command("critical-speed")(critical_speed)
    app.command("map")(map_)
    app.command("reproduce")(reproduce)
    bench_app.command("map")(bench_map)
    bench_app.command("critical-speed")(bench_critical_speed)
    bench_app.command("model-map")(bench_model_map)
