"""A 200-point Hopf curve with l1 at every point on the paper's model (issue 28): seconds and points/s.

The curve: ``paper-fig3`` with rigid pads (``k_ip = inf``) and ``mu2 = 0.5`` in ``(mu1, Omega)``, ``Omega`` on a
log axis 10..20000 rad/s, continued from its crossing at ``Omega = 1000`` rad/s with a fixed step (0.004 of the
box) so that it has about 200 points (100 each way), through its generalised-Hopf point.  Measured in one
process, warm (the model's code loaded and a short curve run once before timing):

* :func:`brakesqueal.region.continue_hopf_curve` with ``lyapunov=True``: ``l1`` at every point by
  :func:`brakesqueal.nonlinear.implicit.lyapunov_at_hopf` (the corrected point, its eigenvalue and the curve's
  ``d lambda / dp`` passed in; double-precision eigenvalues where their error bounds decide) (target: <= 5 s);
* the baseline, the previous per-point route in the same process: the same call with every ``l1`` (the
  generalised-Hopf bisection's included) from the full :func:`~brakesqueal.nonlinear.implicit.exact_lyapunov`
  (extended-precision pair selection, chord refinement with finite-difference ``d lambda / dp``, extended-precision
  eigenvalues, the silent motion's derivative, the events);
* the continuation alone (``lyapunov=False``), for reference;
* (skipped with ``--no-diagram``) the Fig. 3 region diagram end to end, as a user runs it (the
  command of the docs' gallery, ``brakesqueal region --preset paper-fig3 --set k_ip=inf --set mu2=0.5
  --x mu1=0:1 --y Omega=10:20000:log --plot region.png --out region.nc`` in a fresh process, code cache warm:
  seeds, curves with l1, GH point, fold-of-cycles slices, certified map, figure, NetCDF) (target: <= 60 s),
  against the same command without the fold-of-cycles slices (``--no-folds``), run the same way.

The largest difference of the two routes' ``l1`` in units of the reported ``l1_error`` and the distance of their
generalised-Hopf points (unit box) are printed with the timings, and the process CPU time of one run of each (the
wall time on a machine shared with other jobs can be several times it).

Run by ``make bench`` (``python -m benchmarks``) or directly:
``python benchmarks/bench_region.py [--points N] [--no-diagram]``.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import BenchResult, best_time, emit  # noqa: E402


def _full_route_l1(engine: Any, space: Any, fld: Any, u: Any, lam: complex, scale: float,
                   use_cache: bool) -> tuple[float | None, float | None, str, str]:
    """The previous ``region.curves._l1``: the full ``exact_lyapunov`` at the point (path: the parameter with the
    larger partial derivative of ``Re lambda``, the pair nearest the curve's frequency)."""
    import numpy as np

    from brakesqueal.errors import BrakesquealError
    from brakesqueal.nonlinear.implicit import exact_lyapunov
    from brakesqueal.region.curves import _grad

    xv, yv = fld.values(u)
    xa, ya = fld.axes
    grad = _grad(fld, u, lam, scale)
    along_y = grad is None or abs(grad[1]) >= abs(grad[0])
    fixed, path, value = ((xa.name, xv), ya.name, yv) if along_y else ((ya.name, yv), xa.name, xv)
    try:
        ex = exact_lyapunov(engine, space.with_values({fixed[0]: fixed[1]}), path, value, omega=lam.imag,
                            use_cache=use_cache)
    except (BrakesquealError, np.linalg.LinAlgError, ValueError) as exc:
        return None, None, "unknown", f"no l1: {exc}"
    h = ex.hopf
    return float(h.l1), float(h.l1_error), h.criticality, "; ".join(h.warnings)


REGION_FIG3 = ["region", "--preset", "paper-fig3", "--set", "k_ip=inf", "--set", "mu2=0.5", "--x", "mu1=0:1",
               "--y", "Omega=10:20000:log", "--no-progress"]


def diagram() -> list[BenchResult]:
    """The Fig. 3 region diagram end to end in a fresh process (code cache warm), against ``--no-folds``."""
    import subprocess
    import tempfile

    def command(*extra: str) -> float:
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-m", "brakesqueal", *REGION_FIG3, *extra,
                            "--plot", str(Path(tmp) / "region.png"), "--out", str(Path(tmp) / "region.nc")],
                           check=True, stdout=subprocess.DEVNULL)
            return time.perf_counter() - t0

    command("--no-folds")  # warm the code cache
    t_full = min(command() for _ in range(2))
    t_base = min(command("--no-folds") for _ in range(2))
    return [BenchResult("Fig. 3 region diagram end to end: brakesqueal region --preset paper-fig3 --set k_ip=inf "
                        "--set mu2=0.5 --x mu1=0:1 --y Omega=10:20000:log --plot --out (fresh process, warm cache)",
                        t_full, "s", t_base, t_full / t_base,
                        {"baseline": "the same command with --no-folds (no fold-of-cycles slices)",
                         "target": "<= 60 s", "machine": "2 vCPU shared with other jobs (noisy)"})]


def run(points: int = 200) -> list[BenchResult]:
    import brakesqueal as bs
    from brakesqueal.analysis.maps import Axis
    from brakesqueal.region import continue_hopf_curve
    from brakesqueal.region import curves as curves_mod

    space = bs.resolve_space(preset="paper-fig3", sets={"k_ip": math.inf, "mu2": 0.5})
    eng = bs.engine(space)
    x, y = Axis("mu1", 0.0, 1.0), Axis("Omega", 10.0, 20000.0, log=True)
    x0 = bs.crossings(space.with_values({"Omega": 1000.0}), x).crossings[0][0]  # 0.15 of the box below the GH point
    half = points // 2
    kw: dict[str, Any] = dict(ds=0.004, ds_max=0.004, max_points=half)

    def curve(lyapunov: bool = True) -> Any:
        return continue_hopf_curve(eng, space, x, y, x0, 1000.0, lyapunov=lyapunov, **kw)

    continue_hopf_curve(eng, space, x, y, x0, 1000.0, max_points=3)  # warm: kernels, code cache
    c0 = time.process_time()
    new = curve()
    cpu_new = time.process_time() - c0
    t_new = best_time(curve, repeat=3)
    t_cont = best_time(lambda: curve(False), repeat=3)
    fast = curves_mod._l1
    curves_mod._l1 = _full_route_l1  # the previous per-point route, same process
    try:
        c0 = time.process_time()
        old = curve()
        cpu_old = time.process_time() - c0
        t_old = best_time(curve, repeat=2)
    finally:
        curves_mod._l1 = fast
    n = len(new.points)
    worst = max((abs(a.l1 - b.l1) / b.l1_error for a, b in zip(new.points, old.points)
                 if a.l1 is not None and b.l1 is not None and b.l1_error), default=math.nan)

    def unit(ax: Axis, v: float) -> float:
        if ax.log:
            return (math.log10(v) - math.log10(ax.start)) / (math.log10(ax.stop) - math.log10(ax.start))
        return (v - ax.start) / (ax.stop - ax.start)

    gh_new = [s for s in new.special_points if s.type == "GH"]
    gh_old = [s for s in old.special_points if s.type == "GH"]
    gh_shift = math.nan
    if len(gh_new) == len(gh_old) == 1:
        (gn,), (go,) = gh_new, gh_old
        gh_shift = max(abs(unit(x, gn.x) - unit(x, go.x)), abs(unit(y, gn.y) - unit(y, go.y)))
    common = {"points": n, "ends": list(new.ends), "special_points": [s.type for s in new.special_points],
              "machine": "2 vCPU shared with other jobs (noisy)"}
    return [
        BenchResult(f"{n}-point Hopf curve with l1 at every point, paper-fig3 (mu1, Omega) (warm)", t_new, "s",
                    t_old, t_new / t_old,
                    {**common, "points_per_s": round(n / t_new, 1), "baseline_points_per_s": round(n / t_old, 1),
                     "cpu_s": round(cpu_new, 2), "baseline_cpu_s": round(cpu_old, 2),
                     "baseline": "the same curve with every l1 from the full exact_lyapunov, same process",
                     "max |l1 - l1_full| / l1_error": float(f"{worst:.3g}"),
                     "GH distance from the full route's (unit box)": float(f"{gh_shift:.3g}"),
                     "target": "<= 5 s"}),
        BenchResult("the same curve without l1 (continuation alone)", t_cont, "s", t_new, t_cont / t_new,
                    {"baseline": "the curve with l1"}),
    ]


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--points", type=int, default=200, help="points of the curve (half each way from the start)")
    ap.add_argument("--no-diagram", action="store_true", help="skip the Fig. 3 region diagram end to end")
    a = ap.parse_args()
    emit(run(a.points) + ([] if a.no_diagram else diagram()))
