"""Max Re λ and frequency of the 2-DOF model on a map: compiled quartic roots vs LAPACK companion eigenvalues.

Both routes start from the same certified kernel's row tables (paper-fig2,
k_ip x mu); the baseline, run in the same process, is the route maps used
before: balanced companion matrices and :func:`numpy.linalg.eigvals`
(:func:`brakesqueal.analysis.robust.roots_summary`).  Also the end-to-end
:func:`~brakesqueal.analysis.maps.stability_map` rate with eigen quantities.

Run by ``make bench`` (``python -m benchmarks``) or directly:
``python benchmarks/bench_map_eigen.py [--size N]``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import BenchResult, best_time, emit  # noqa: E402
from brakesqueal.codegen import build


def run(size: int = 2000) -> list[BenchResult]:
    from brakesqueal.analysis.kernels import kernel_eigen, kernel_scaling
    from brakesqueal import Axis, stability_map
    from brakesqueal.analysis.robust import roots_summary
    from brakesqueal.model import ParameterSpace

    space = ParameterSpace.from_preset("paper-fig2")
    x, y = Axis("k_ip", 1e5, 1e10, size, True), Axis("mu", 0.05, 1.0, size)
    kern = build(space.model).map_kernel(space, x.name, y.name)
    assert kern is not None
    ax = {x.name: x, y.name: y}
    ov, iv = ax[kern.outer].values(), ax[kern.inner].values()
    e, t = kernel_scaling(kern, iv)
    C, _, lam_e = kern.row_tables(ov, e)
    kernel_eigen(kern, C[:2], t, lam_e[:2])
    t_fast = best_time(lambda: kernel_eigen(kern, C, t, lam_e), repeat=3)
    rate = ov.size * iv.size / t_fast
    # baseline: companion eigenvalues of the same quartics (a 200-row slice)
    rows = 200
    A = np.empty((5, rows, t.size))
    kern.coefficients(C[:rows], t, A)
    Q = np.ascontiguousarray(A.transpose(1, 2, 0).reshape(-1, 5))
    t_base = best_time(lambda: roots_summary(Q), repeat=3)
    base = Q.shape[0] / t_base
    _, _, found = kernel_eigen(kern, C, t, lam_e)  # agreement with LAPACK: tests/analysis/test_map_speed.py
    small = (Axis("k_ip", 1e5, 1e10, 1000, True), Axis("mu", 0.05, 1.0, 1000))
    stability_map(space, *small)
    t_map = best_time(lambda: stability_map(space, *small), repeat=3)
    return [
        BenchResult("2-DOF max Re λ + frequency, compiled quartic roots (kernel rows)", rate, "points/s", base,
                    rate / base, {"grid": f"{size}x{size}", "best_time_s": round(t_fast, 4),
                                  "found_fraction": round(float(found.mean()), 6),
                                  "baseline": "balanced companion matrices + numpy.linalg.eigvals (same quartics)",
                                  "target": ">= 2e7 points/s"}),
        BenchResult("stability_map 1000x1000 with max_real and frequency (Dataset, in process)", 1e6 / t_map,
                    "points/s", base, 1e6 / t_map / base, {"best_time_s": round(t_map, 3)}),
    ]


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--size", type=int, default=2000)
    emit(run(ap.parse_args().size))
