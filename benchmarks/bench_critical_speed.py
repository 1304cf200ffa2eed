"""Critical speeds per second (every crossing in 1..1e5 rad/s) on random ``paper-fig3`` sets: the certified
compiled Laurent-polynomial kernel against a numeric scan of max Re(lambda) + brentq in the same run.

Run by ``make bench`` (``python -m benchmarks``) or directly: ``python benchmarks/bench_critical_speed.py [--n N]``.
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


def run(n: int = 100000) -> list[BenchResult]:
    from scipy.optimize import brentq

    from brakesqueal.analysis.crossings import critical_speeds_batch
    from brakesqueal import linearize
    from brakesqueal.model import ParameterSpace

    rng = np.random.default_rng(1)
    mu1 = rng.uniform(0.05, 0.95, n)
    kip = 10 ** rng.uniform(6.5, 10, n)
    space = ParameterSpace.from_preset("paper-fig3")
    arr = space.arrays({"mu1": mu1, "mu2": 1 - mu1, "k_ip": kip})  # eqs. 57 and 63 per row, as the preset ties them
    P = np.ascontiguousarray(np.stack([np.broadcast_to(v, (n,)) for v in space.vectors(arr)], axis=1))
    import numba

    critical_speeds_batch(build(space.model), P[:10], 1.0, 1e5)
    critical_speeds_batch(build(space.model), P[:5000], 1.0, 1e5)  # the parallel driver (chunks of sets)
    t = best_time(lambda: critical_speeds_batch(build(space.model), P, 1.0, 1e5), repeat=3)
    rate = n / t
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        t1 = best_time(lambda: critical_speeds_batch(build(space.model), P, 1.0, 1e5), repeat=3)
    finally:
        numba.set_num_threads(threads)
    m = 5  # baseline: log-grid scan of max Re(lambda) (numeric linearization) + brentq, a few sets
    t0 = time.perf_counter()
    for i in range(m):
        prm = space.resolve({"mu1": float(mu1[i]), "mu2": float(1 - mu1[i]), "k_ip": float(kip[i])})

        def f(W: float) -> float:
            return linearize(prm.replace(Omega=W)).max_real

        grid = np.logspace(0, 5, 200)
        vals = [f(W) for W in grid]
        for a, b, fa, fb in zip(grid, grid[1:], vals, vals[1:]):
            if fa * fb < 0:
                brentq(f, a, b, rtol=1e-12)
    base = m / (time.perf_counter() - t0)
    return [BenchResult("critical speeds: compiled Laurent-Hurwitz kernel, all crossings in 1..1e5 rad/s",
                        rate, "sets/s", base, rate / base,
                        {"sets": n, "best_time_s": round(t, 4), "threads": threads,
                         "one_thread_sets_per_s": round(n / t1), "target": ">= 5e5 sets/s (issue 13)",
                         "baseline": "200-point log scan of max Re lambda (numeric linearization) + brentq",
                         "note": "random paper-fig3 sets (mu1 in 0.05..0.95, "
                                                              "k_ip 10^6.5..10^10)"})]


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--n", type=int, default=100000, help="points of the batch, in [1, 10^8]")
    n = ap.parse_args().n
    if not 1 <= n <= 10**8:
        ap.error(f"--n must be in [1, 10^8]; got {n}")
    emit(run(n))
