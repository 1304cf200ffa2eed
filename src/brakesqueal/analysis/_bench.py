"""``brakesqueal bench map`` and ``bench critical-speed``: package kernels vs baselines in one run."""

from __future__ import annotations

import math
import resource
import time

import numpy as np

from ..bench import BenchResult, best_time

__all__ = ["bench_map", "bench_critical_speed"]


def _naive_eigvals_rate(space, kip: np.ndarray, mu: np.ndarray, n: int) -> float:  # type: ignore[no-untyped-def]
    """Per-point loop: build Mbar, Dbar, Kbar (compiled scalar closed form) and call scipy.linalg.eigvals."""
    import scipy.linalg

    from ..numeric.compiled import compiled_model
    from .equilibrium import parameter_vector
    from .linear import state_matrix

    tm = compiled_model().vectorized.trivial_matrices
    pts = [(float(kip[i % kip.size]), float(mu[(7 * i) % mu.size])) for i in range(n)]
    params = [parameter_vector(space.resolve({"k_ip": a, "mu": b})) for a, b in pts]
    t0 = time.perf_counter()
    for p in params:
        e = np.asarray(tm(p), dtype=float)
        A = state_matrix(e[0:4].reshape(2, 2), e[4:8].reshape(2, 2), e[8:12].reshape(2, 2))
        _ = bool(scipy.linalg.eigvals(A).real.max() < 0)
    return n / (time.perf_counter() - t0)


def bench_map(*, size: int = 4000, large: bool = False) -> list[BenchResult]:
    """Stability-map throughput: compiled Hurwitz kernel, NumPy path, Dataset path, naive baseline."""
    from ..numeric.compiled import compiled_model
    from .kernels import hurwitz_stable, inner_exponent, kernel_segments, map_kernel, quartic_coefficients
    from .maps import Axis, stability_map
    from .space import VECTOR_NAMES, ParameterSpace

    space = ParameterSpace.from_preset("paper-fig2")
    x, y = Axis("k_ip", 1e5, 1e10, size, True), Axis("mu", 0.05, 1.0, size)
    t0 = time.perf_counter()
    kern = map_kernel(space, x.name, y.name)
    build = time.perf_counter() - t0
    assert kern is not None
    ax = {x.name: x, y.name: y}
    outer, inner = ax[kern.outer], ax[kern.inner]
    ov, iv = outer.values(), inner.values()
    out = np.empty((ov.size, iv.size), dtype=np.uint8)
    e = inner_exponent(iv)
    t_in = np.ldexp(iv, -e)

    def run() -> None:
        C, EC = kern.row_coefficients(ov, e)  # coefficient tables (with error bounds) built from the axes each time
        seg, T = kernel_segments(t_in)
        kern.classify(C, EC, t_in, seg, T, out)  # certified codes: 0 unstable, 1 stable, 2 uncertain

    run()
    t_kernel = best_time(run, repeat=5)
    rate = ov.size * iv.size / t_kernel
    base = _naive_eigvals_rate(space, x.values(), y.values(), 3000)
    # vectorized NumPy path (no compiler): closed-form matrices + quartic + Hurwitz on arrays
    tm = compiled_model().vectorized.trivial_matrices
    sub_o, sub_i = ov[:250, None], iv[None, :]
    arr = space.arrays({outer.name: sub_o, inner.name: sub_i})
    p = [arr[n] for n in VECTOR_NAMES]

    def run_np() -> None:
        e = tm(p)
        M = np.stack([np.broadcast_to(v, arr["mu1"].shape) for v in e[0:4]], -1).reshape(*arr["mu1"].shape, 2, 2)
        D = np.stack([np.broadcast_to(v, arr["mu1"].shape) for v in e[4:8]], -1).reshape(*arr["mu1"].shape, 2, 2)
        K = np.stack([np.broadcast_to(v, arr["mu1"].shape) for v in e[8:12]], -1).reshape(*arr["mu1"].shape, 2, 2)
        hurwitz_stable(*quartic_coefficients(M, D, K))

    t_np = best_time(run_np, repeat=3)
    rate_np_generic = sub_o.size * sub_i.size / t_np
    from .kernels import classify_numpy

    C_sub, EC_sub = kern.row_coefficients(ov[:250], e)
    t_np = best_time(lambda: classify_numpy(kern, C_sub, EC_sub, t_in), repeat=3)
    rate_np = 250 * iv.size / t_np
    small = (Axis("k_ip", 1e5, 1e10, 300, True), Axis("mu", 0.05, 1.0, 200))
    stability_map(space, *small)
    t_ds = best_time(lambda: stability_map(space, *small), repeat=3)
    rate_ds = 300 * 200 / t_ds
    res = [
        BenchResult("map: certified compiled Hurwitz kernel (paper-fig2, k_ip x mu)", rate, "points/s", base,
                    rate / base,
                    {"grid": f"{size}x{size}", "best_time_s": round(t_kernel, 5),
                     "uncertain_points": int(np.count_nonzero(out == 2)),
                     "kernel_build_s_incl_sympy_and_load": round(build, 3),
                     "baseline": "naive per-point loop: closed-form matrices + scipy.linalg.eigvals",
                     "target": ">= 3e8 points/s and >= 1e4 x baseline"}),
        BenchResult("map: vectorized NumPy path (no compiler)", rate_np, "points/s", base, rate_np / base,
                    {"points": 250 * int(iv.size), "target": ">= 3e7 points/s",
                     "same_row_coefficients_as_kernel": True,
                     "generic_numpy_path_points_per_s (closed-form matrices per point)": round(rate_np_generic)}),
        BenchResult("map: full Dataset (verdict + max_real + frequency)", rate_ds, "points/s", base, rate_ds / base,
                    {"grid": "300x200", "note": "quartic roots by batched companion eigenvalues"}),
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


def bench_critical_speed(*, n: int = 100000) -> list[BenchResult]:
    """Critical speeds (all crossings in 1..1e5 rad/s): compiled kernel vs eigenvalue bisection."""
    from scipy.optimize import brentq

    from .equilibrium import parameter_vector
    from .kernels import critical_speeds_batch
    from .linear import linearize
    from .space import ParameterSpace

    rng = np.random.default_rng(1)
    mu1 = rng.uniform(0.05, 0.95, n)
    kip = 10 ** rng.uniform(6.5, 10, n)
    base_space = ParameterSpace.from_preset("paper-fig3")
    P = np.empty((n, 17))
    ref = np.array(parameter_vector(base_space.resolve({})))
    # eq. 57 / 63 per row (same relations as the preset, vectorized)
    h = 0.02
    P[:] = ref
    mu2 = 1 - mu1
    h10, h20 = h * mu2, h * mu1
    P[:, 10], P[:, 11], P[:, 12], P[:, 13] = mu1, mu2, h10, h20
    P[:, 0] = 0.16 + 0.32 / (2 * 0.15 ** 2) * (h10 - h20) ** 2
    P[:, 8] = P[:, 9] = 1 / kip
    critical_speeds_batch(P[:10], 1.0, 1e5)
    t = best_time(lambda: critical_speeds_batch(P, 1.0, 1e5), repeat=3)
    rate = n / t
    # baseline: log-grid scan of max Re λ (numeric linearization) + brentq to 1e-10, a few points
    m = 5
    t0 = time.perf_counter()
    for i in range(m):
        prm = base_space.resolve({"mu1": float(mu1[i]), "mu2": float(mu2[i]), "k_ip": float(kip[i])})
        f = lambda W: linearize(prm.replace(Omega=W)).max_real  # noqa: E731
        grid = np.logspace(0, 5, 200)
        vals = [f(W) for W in grid]
        for a, b, fa, fb in zip(grid, grid[1:], vals, vals[1:]):
            if fa * fb < 0:
                brentq(f, a, b, rtol=1e-12)
    base = m / (time.perf_counter() - t0)
    return [BenchResult("critical speeds: compiled Laurent-Hurwitz kernel, all crossings in 1..1e5 rad/s",
                        rate, "sets/s", base, rate / base,
                        {"sets": n, "best_time_s": round(t, 4),
                         "baseline": "200-point log scan of max Re lambda (numeric linearization) + brentq",
                         "target": ">= 1e5 sets/s, relative accuracy <= 1e-10", "range_rad_s": "1..1e5",
                         "note": f"{math.nan if n == 0 else n} random paper-fig3 sets (mu1 in 0.05..0.95, k_ip 10^6.5..10^10)"})]
