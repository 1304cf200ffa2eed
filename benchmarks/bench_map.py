"""Stability-map throughput on ``paper-fig2`` (k_ip x mu): the certified compiled kernel, the full Dataset
path and, with ``--large``, a chunked 1e8-point map with its peak memory, against a naive per-point loop.

Run by ``make bench`` (``python -m benchmarks``) or directly:
``python benchmarks/bench_map.py [--size N] [--large]``.
"""

from __future__ import annotations

import argparse
import resource
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import BenchResult, best_time, emit  # noqa: E402
from brakesqueal.codegen import build


def naive_rate(space, kip: np.ndarray, mu: np.ndarray, n: int) -> float:  # type: ignore[no-untyped-def]
    """Per-point loop: M, D, K of the zero state (compiled model) and scipy.linalg.eigvals of the state matrix."""
    import scipy.linalg

    from brakesqueal.analysis.linear import state_matrix
    from brakesqueal.codegen import compile_model

    cm = compile_model(space.model)
    pts = [(float(kip[i % kip.size]), float(mu[(7 * i) % mu.size])) for i in range(n)]
    params = [[float(v) for v in space.resolve({"k_ip": a, "mu": b}).vector()] for a, b in pts]
    t0 = time.perf_counter()
    for p in params:
        M, D, K = cm.zero_linear(p)
        _ = bool(scipy.linalg.eigvals(state_matrix(M, D, K)).real.max() < 0)
    return n / (time.perf_counter() - t0)


def run(size: int = 4000, large: bool = False) -> list[BenchResult]:
    from brakesqueal import Axis, stability_map
    from brakesqueal.codegen.stability import inner_exponent, kernel_segments
    from brakesqueal.model import ParameterSpace

    space = ParameterSpace.from_preset("paper-fig2")
    x, y = Axis("k_ip", 1e5, 1e10, size, True), Axis("mu", 0.05, 1.0, size)
    t0 = time.perf_counter()
    kern = build(space.model).map_kernel(space, x.name, y.name)
    t_build = time.perf_counter() - t0
    assert kern is not None
    ax = {x.name: x, y.name: y}
    outer, inner = ax[kern.outer], ax[kern.inner]
    ov, iv = outer.values(), inner.values()
    out = np.empty((ov.size, iv.size), dtype=np.uint8)
    e = inner_exponent(iv)
    t_in = np.ldexp(iv, -e)

    def kernel() -> None:
        C, EC = kern.row_coefficients(ov, e)  # coefficient tables (with error bounds) built from the axes each time
        seg, T = kernel_segments(t_in)
        kern.classify(C, EC, t_in, seg, T, out)  # certified codes: 0 unstable, 1 stable, 2 uncertain

    kernel()
    t_kernel = best_time(kernel, repeat=5)
    rate = ov.size * iv.size / t_kernel
    base = naive_rate(space, x.values(), y.values(), 3000)
    small = (Axis("k_ip", 1e5, 1e10, 300, True), Axis("mu", 0.05, 1.0, 200))
    stability_map(space, *small)
    t_ds = best_time(lambda: stability_map(space, *small, boundary=False), repeat=3)
    rate_ds = 300 * 200 / t_ds
    t_vo = best_time(lambda: stability_map(space, *small, eigen=False, boundary=False), repeat=3)
    t_b = best_time(lambda: stability_map(space, *small), repeat=3) - t_ds  # the refined stability boundary
    res = [
        BenchResult("map: certified compiled Hurwitz kernel (paper-fig2, k_ip x mu)", rate, "points/s", base,
                    rate / base,
                    {"grid": f"{size}x{size}", "best_time_s": round(t_kernel, 5),
                     "uncertain_points": int(np.count_nonzero(out == 2)),
                     "kernel_build_s_incl_sympy_and_load": round(t_build, 3),
                     "baseline": "naive per-point loop: zero-state M, D, K + scipy.linalg.eigvals",
                     "target": ">= 1e9 points/s"}),
        BenchResult("map: full Dataset (verdict + max_real + frequency)", rate_ds, "points/s", base, rate_ds / base,
                    {"grid": "300x200", "verdict_only_points_per_s": round(300 * 200 / t_vo),
                     "boundary_refinement_s": round(t_b, 4)}),
    ]
    if large:
        big = (Axis("k_ip", 1e5, 1e10, 10000, True), Axis("mu", 0.05, 1.0, 10000))
        t0 = time.perf_counter()
        stability_map(space, *big, eigen=False)
        t_big = time.perf_counter() - t0
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20
        res.append(BenchResult("map: 1e8-point chunked map (verdict only, Dataset)", 1e8 / t_big, "points/s", base,
                               1e8 / t_big / base, {"seconds": round(t_big, 2),
                                                    "peak_rss_GiB_whole_process": round(peak, 3)}))
    return res


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--size", type=int, default=4000)
    ap.add_argument("--large", action="store_true")
    a = ap.parse_args()
    emit(run(a.size, a.large))
