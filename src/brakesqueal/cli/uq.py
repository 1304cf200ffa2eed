"""``brakesqueal uq``: Squeal as a probability (issue 27): Sobol' indices and P(squeal) of a study file with
``[distributions]`` (:mod:`brakesqueal.uq`)."""

from __future__ import annotations

import json
import sys
from enum import Enum
from typing import Annotated, Any, Optional

import typer

from ._options import PLOT_SUFFIXES, FormatOpt, OutFormat, ProgressOpt

__all__ = ["register"]


class _Backend(str, Enum):
    scipy = "scipy"
    salib = "salib"


class _Surrogate(str, Enum):
    pce = "pce"


class _SurrogateQuantity(str, Enum):
    max_real = "max_real"
    margin = "margin"
    onset_l1 = "onset_l1"
    onset_amplitude = "onset_amplitude"


def uq(
    study: Annotated[str, typer.Argument(help="Study file (TOML) with [distributions] and [samples] n, seed.")],
    out: Annotated[Optional[str], typer.Option("--out", help="Write the indices, P(squeal) and the A/B samples "
                                                             "as NetCDF (.nc).")] = None,
    plot: Annotated[Optional[str], typer.Option("--plot", help="Histograms and the index bar chart "
                                                               "(.png, .svg, .pdf).")] = None,
    backend: Annotated[_Backend, typer.Option("--backend", help="Sobol' estimator: scipy "
                                                                "(scipy.stats.sobol_indices) or salib.")
                       ] = _Backend.scipy,
    store: Annotated[Optional[str], typer.Option("--store", help="Zarr store of the design's evaluations "
                                                                 "(resumable; default: STUDY.uq.zarr for large "
                                                                 "designs or with --workers/--scheduler, else in "
                                                                 "memory).")] = None,
    workers: Annotated[Optional[int], typer.Option("--workers", help="Local Dask worker processes (as sweep).")
                       ] = None,
    scheduler: Annotated[Optional[str], typer.Option("--scheduler", help="Address of a Dask scheduler.")] = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help="Replace an existing store.")] = False,
    confidence: Annotated[float, typer.Option("--confidence", help="Confidence level of the intervals.")] = 0.95,
    resamples: Annotated[int, typer.Option("--resamples", help="Bootstrap resamples.")] = 999,
    surrogate: Annotated[Optional[_Surrogate], typer.Option("--surrogate", help="Also fit a polynomial chaos "
                                                                               "surrogate of max Re lambda to a "
                                                                               "few hundred runs and report its "
                                                                               "indices and P(squeal) beside the "
                                                                               "Monte Carlo ones.")] = None,
    degree: Annotated[int, typer.Option("--degree", help="Total degree of the surrogate (1-20).")] = 4,
    sparse: Annotated[bool, typer.Option("--sparse", help="Select the surrogate's terms by orthogonal matching "
                                                          "pursuit (least leave-one-out error).")] = False,
    surrogate_runs: Annotated[int, typer.Option("--surrogate-runs", help="Runs the surrogate is fitted to "
                                                                         "(10-65536).")] = 256,
    surrogate_quantity: Annotated[_SurrogateQuantity, typer.Option(
        "--surrogate-quantity", help="What the surrogate approximates: max_real, margin, or at the squeal onset "
                                     "along the spin rate the first Lyapunov coefficient (onset_l1: P(subcritical) "
                                     "from its sign) or the cycles' amplitude growth coefficient "
                                     "(onset_amplitude); the onset quantities take about 0.1 s a run.")
                                  ] = _SurrogateQuantity.max_real,
    modes: Annotated[bool, typer.Option("--modes", help="Also the indices of the real part and the frequency "
                                                        "of every tracked mode (modes numbered by ascending "
                                                        "frequency at every point).")] = False,
    progress: ProgressOpt = None,
    fmt: FormatOpt = OutFormat.text,
) -> None:
    """Sobol' indices (first, total) of max Re lambda, squeal and frequency, and P(squeal), with intervals."""
    from ..errors import ParameterError
    from ..outputs import atomic_write, check_output
    from ..sweep.runner import check_scheduler_address
    from ..uq import plot_uq, run_uq, uq_summary

    if out:
        check_output(out, what="--out", suffixes=(".nc",))
    if plot:
        check_output(plot, what="--plot", suffixes=PLOT_SUFFIXES)
    if not 0 < confidence < 1:
        raise ParameterError(f"--confidence must be in (0, 1); got {confidence!r}")
    if not 10 <= resamples <= 100000:
        raise ParameterError(f"--resamples must be in [10, 100000]; got {resamples}")
    if scheduler is not None:
        scheduler = check_scheduler_address(scheduler)
    if surrogate is not None:
        _check_surrogate(study, degree, sparse, surrogate_runs)
    from ._progress import progress as _progress

    with _progress("uq", progress) as cb:
        run = run_uq(study, store=store, workers=workers, scheduler=scheduler, overwrite=overwrite,
                     backend=backend.value, confidence=confidence, n_resamples=resamples, progress=cb,
                     per_mode=modes)
    ds = run.dataset
    sur = None
    if surrogate is not None:
        from ..uq import fit_study_pce

        sq = surrogate_quantity.value
        sur = fit_study_pce(study, runs=surrogate_runs, degree=degree, sparse=sparse, quantity=sq).summary()
        names = [str(x) for x in ds["input"].values]
        ds = ds.assign(surrogate_first=("input", [_nan(sur["first"][n]) for n in names],
                                        {"long_name": f"first-order Sobol' index of {sq} from the polynomial "
                                                      "chaos surrogate"}),
                       surrogate_total=("input", [_nan(sur["total"][n]) for n in names],
                                        {"long_name": f"total Sobol' index of {sq} from the surrogate"}))
        ds.attrs.update({f"surrogate_{k}": ("" if v is None else v) for k, v in sur.items()
                         if k not in ("first", "total")})
    if out:
        nc = ds.assign_coords(quantity=ds["quantity"].astype("S"), input=ds["input"].astype("S"),
                              bound=ds["bound"].astype("S"), point_status=ds["point_status"].astype("S"))
        with atomic_write(out, what="--out") as tmp:
            nc.to_netcdf(str(tmp), engine="scipy")
    if plot:
        with atomic_write(plot, what="--plot") as tmp:
            plot_uq(ds).savefig(tmp, dpi=150)
    summary = uq_summary(ds)
    if sur is not None:
        summary["surrogate"] = sur
    if fmt == OutFormat.json:
        sys.stdout.write(json.dumps(summary, indent=2) + "\n")
        return
    sys.stdout.write(_text(summary))


#: Tracked modes whose indices the text output lists (all of them in JSON and NetCDF).
TEXT_MODES = 6


def _f(x: Any) -> str:
    return "n/a" if x is None else f"{x:.3f}"


def _nan(x: Any) -> float:
    return float("nan") if x is None else float(x)


def _check_surrogate(study: str, degree: int, sparse: bool, runs: int) -> None:
    """Refuse surrogate options before the Monte Carlo run (one line naming the option)."""
    from ..errors import ParameterError
    from ..sweep import load_study
    from ..uq import pce_basis_size

    if not 1 <= degree <= 20:
        raise ParameterError(f"--degree must be in [1, 20]; got {degree}")
    if not 10 <= runs <= 1 << 16:
        raise ParameterError(f"--surrogate-runs must be in [10, {1 << 16}]; got {runs}")
    d = len(load_study(study).ranges)
    terms = pce_basis_size(max(d, 1), degree)
    if not sparse and runs < 2 * terms:
        raise ParameterError(f"--surrogate-runs {runs} is too few for --degree {degree} in {d} inputs ({terms} "
                             f"terms): least squares needs at least {2 * terms}; give more runs, a lower degree "
                             "or --sparse")


def _index_lines(v: dict[str, Any], inputs: list[str], width: int) -> list[str]:
    """One line per input: its first and total Sobol' indices of one quantity ``v``, with their intervals."""
    lines = []
    for nm in inputs:
        lo, hi = v["first_ci"][nm]
        tlo, thi = v["total_ci"][nm]
        lines.append(f"  {nm:<{width}}  first {_f(v['first'][nm])} [{_f(lo)}, {_f(hi)}]   "
                     f"total {_f(v['total'][nm])} [{_f(tlo)}, {_f(thi)}]")
    return lines


def _text(s: dict[str, Any]) -> str:
    lines = [f"{s['study']}: {s['evaluations']} evaluations (N = {s['n_base']}, {len(s['inputs'])} inputs), "
             f"backend {s['backend']}, {100 * s['confidence']:g} % intervals"]
    p = s["p_squeal"]
    lines.append(f"P(squeal) = {_f(p['value'])} [{_f(p['ci'][0])}, {_f(p['ci'][1])}] "
                 f"({p['squealing']} of {p['with_verdict']} samples with a verdict)")
    if s["no_verdict"]:
        lines.append(f"{s['no_verdict']} design points without a verdict ("
                     + ", ".join(f"{k}: {v}" for k, v in s["status_counts"].items() if not k.startswith("ok"))
                     + f"); P(squeal) between {_f(p['bounds'][0])} and {_f(p['bounds'][1])}")
    width = max(len(n) for n in s["inputs"])
    for q, v in s["quantities"].items():
        lines.append(f"{q} ({v['rows']} rows):")
        lines += _index_lines(v, s["inputs"], width)
    modes = s.get("modes", [])
    for m in modes[:TEXT_MODES]:
        for part in ("real", "frequency"):
            v = m[part]
            lo_f, hi_f = m["frequency_range"]
            lines.append(f"mode {m['mode']} {part} ({v['rows']} rows; {_f(lo_f)} to {_f(hi_f)} Hz):")
            lines += _index_lines(v, s["inputs"], width)
    if len(modes) > TEXT_MODES:
        lines.append(f"({len(modes) - TEXT_MODES} more modes in --format json and --out)")
    sur = s.get("surrogate")
    if sur:
        prob = (f": P(squeal) = {_f(sur['p_squeal'])}" if "p_squeal" in sur and sur["p_squeal"] is not None else
                f": P(subcritical onset) = {_f(sur['p_subcritical'])}" if "p_subcritical" in sur else "")
        lines.append(f"surrogate of {sur['quantity']} ({sur['method']}, degree {sur['degree']}, {sur['terms']} of "
                     f"{sur['candidates']} terms, {sur['runs']} runs, {sur['left_out']} left out, leave-one-out "
                     f"error {sur['loo_error']:.2e}){prob}")
        for nm in s["inputs"]:
            lines.append(f"  {nm:<{width}}  first {_f(sur['first'][nm])}   total {_f(sur['total'][nm])}")
    return "\n".join(lines) + "\n"


def register(app: typer.Typer) -> None:
    """Add ``uq`` to ``app``."""
    app.command("uq")(uq)
