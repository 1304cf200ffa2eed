"""Maps of n-DOF models (``eight-dof``: 8 coordinates, a 16 x 16 state matrix): the compiled
characteristic-polynomial route against the certified eigenvalue route it replaces, in the same run.

Measured:

* the route's kernel alone (:func:`brakesqueal.analysis.kernels.charpoly_verdicts`: exact
  ``det(λ²M + λD + K)`` on the grid, roots by warm-started Weierstrass sweeps, verdicts from Gerschgorin
  inclusion disks), verdict only and with ``max_real``/``frequency``;
* the whole :func:`~brakesqueal.analysis.maps.stability_map` (validity, fallback of undecided points,
  Dataset), without and with the refined stability boundary;
* baseline: the certified eigenvalue route on a sample of the same grid
  (:func:`~brakesqueal.analysis.points.evaluate_arrays` with the polynomial route switched off, i.e.
  batched zero-state ``M, D, K`` and eigenvalues with condition numbers), plus one batched
  ``numpy.linalg.eigvals`` call on as many random 16 x 16 matrices (the floor of any eigenvalue route).

Run by ``make bench`` (``python -m benchmarks``) or directly:
``python benchmarks/bench_model_map.py [--model NAME] [--size N]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import BenchResult, best_time, emit  # noqa: E402
from brakesqueal.codegen import build


def run(model: str = "eight-dof", size: int = 1000) -> list[BenchResult]:
    from brakesqueal.analysis.kernels import charpoly_verdicts
    from brakesqueal import Axis, stability_map
    from brakesqueal.analysis.points import evaluate_arrays
    from brakesqueal.codegen import compile_model
    from brakesqueal.model import resolve_space

    space = resolve_space(model)
    spec = space.model
    names = [k for k in ("k_c", "k_cn", "k_ip1", "k1") if k in spec.parameters][:2]

    def axes(num: int) -> tuple[Axis, Axis]:
        a, b = (spec.parameters[k] for k in names)
        return Axis(names[0], a / 10, a * 10, num, log=True), Axis(names[1], b / 10, b * 10, num, log=True)

    x, y = axes(size)
    pts = size * size
    stability_map(space, *axes(8))  # compile and warm up
    tab = build(space.model).charpoly_table(space, y.name, x.name)
    if tab is None:
        raise SystemExit(f"the characteristic-polynomial route does not apply to {model} over {names}")
    ov, iv = y.values(), x.values()
    charpoly_verdicts(tab, ov[:200], iv, eigen=False)  # compile the parallel driver too
    t_kv = best_time(lambda: charpoly_verdicts(tab, ov, iv, eigen=False), repeat=2)
    t_ke = best_time(lambda: charpoly_verdicts(tab, ov, iv, eigen=True), repeat=2)
    codes_v = charpoly_verdicts(tab, ov, iv, eigen=False)[0]
    codes_e = charpoly_verdicts(tab, ov, iv, eigen=True)[0]
    ms = min(size, 300)
    small = axes(ms)
    t_map = best_time(lambda: stability_map(space, *small, boundary=False), repeat=2)
    t_map_v = best_time(lambda: stability_map(space, *small, eigen=False, boundary=False), repeat=2)
    t_map_b = best_time(lambda: stability_map(space, *small, eigen=False), repeat=1)
    m = stability_map(space, *small, boundary=False).data
    und = int(np.count_nonzero(m["status"].values == 5))
    # baseline: the certified eigenvalue route on a sample of the same grid (same process)
    nb = min(pts, 3000)
    rng = np.random.default_rng(0)
    sel_o, sel_i = ov[rng.integers(0, ov.size, nb)], iv[rng.integers(0, iv.size, nb)]
    arr = space.arrays({y.name: sel_o, x.name: sel_i})
    t0 = time.perf_counter()
    evaluate_arrays(build(space.model), space, arr, eigen=True)
    base = nb / (time.perf_counter() - t0)
    n2 = 2 * compile_model(spec).n
    A = rng.normal(size=(nb, n2, n2))
    t0 = time.perf_counter()
    np.linalg.eigvals(A)
    floor = nb / (time.perf_counter() - t0)
    common = {"grid": f"{size}x{size}", "axes": f"{y.name} (outer) x {x.name} (inner), log, x/10 .. x*10",
              "baseline": "certified eigenvalue route (batched zero-state M, D, K + eig with condition numbers) on "
                          f"{nb} points of the same grid, same run",
              "numpy_eigvals_random_points_per_s": round(floor)}
    return [
        BenchResult(f"n-DOF map kernel ({model}, degree {n2} characteristic polynomial): certified verdicts only",
                    pts / t_kv, "points/s", base, pts / t_kv / base,
                    {**common, "undecided_fraction": float(np.mean(codes_v == 2)), "target": ">= 1e6 points/s"}),
        BenchResult(f"n-DOF map kernel ({model}): verdicts + max Re λ + frequency (every root to 1e-9)",
                    pts / t_ke, "points/s", base, pts / t_ke / base,
                    {"undecided_fraction (recomputed by the eigenvalue route)": float(np.mean(codes_e == 2)),
                     "target": ">= 1e5 points/s"}),
        BenchResult(f"stability_map {ms}x{ms} ({model}) with max_real and frequency, no boundary", ms * ms / t_map,
                    "points/s", base, ms * ms / t_map / base,
                    {"method": m.attrs["method"], "undecided_points": und}),
        BenchResult(f"stability_map {ms}x{ms} ({model}), verdict only (--no-eigen), no boundary", ms * ms / t_map_v,
                    "points/s", base, ms * ms / t_map_v / base, {}),
        BenchResult(f"stability_map {ms}x{ms} ({model}), verdict only, with the refined boundary", ms * ms / t_map_b,
                    "points/s", base, ms * ms / t_map_b / base,
                    {"note": "12 bisection steps per boundary vertex, by the same route at scattered points"}),
    ]


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--model", default="eight-dof")
    ap.add_argument("--size", type=int, default=1000)
    a = ap.parse_args()
    emit(run(a.model, a.size))
