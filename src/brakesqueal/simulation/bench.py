"""``brakesqueal bench simulate``: compiled simulation vs. a straightforward lambdify + solve_ivp baseline."""

from __future__ import annotations

import time
from typing import Any, Callable

import numpy as np

from ..bench import BenchResult, best_time

__all__ = ["bench_simulate", "lambdify_rhs"]


def lambdify_rhs(params: Any) -> Callable[[float, np.ndarray], np.ndarray]:
    """The same RHS as the kernels, built the straightforward way: SymPy ``lambdify`` without CSE.

    The pads' ``l`` is solved by Newton iterations (warm-started) in Python,
    ``q_mddot = -M_m^{-1} psi(q_mddot = 0)`` with NumPy.
    """
    import sympy as sp

    from ..analysis.equilibrium import parameter_vector
    from ..symbolic.model import PARAMETER_SYMBOLS
    from ._kernels import _expressions

    ex = _expressions()
    ys = sp.symbols("q1 q2 dq1 dq2")
    ls = sp.symbols("l1 l2")
    ps = sp.symbols(" ".join(PARAMETER_SYMBOLS))
    mass = sp.lambdify((ys, ls, ps), [sp.sympify(e) for e in ex["mass"]], "numpy")
    gfun = sp.lambdify((ys, ls, ps), [sp.sympify(e) for e in ex["g"]], "numpy")
    p = tuple(parameter_vector(params))
    lbuf = np.zeros(2)

    def fun(t: float, y: np.ndarray) -> np.ndarray:
        yy = tuple(y)
        for _ in range(30):
            g1, g2, g1l, g2l = gfun(yy, tuple(lbuf), p)
            d = np.array([g1 / g1l, g2 / g2l])
            lbuf[:] -= d
            if np.all(np.abs(d) <= 1e-13 * np.abs(lbuf) + 1e-300):
                break
        m11, m12, m21, m22, f1, f2 = mass(yy, tuple(lbuf), p)
        acc = -np.linalg.solve(np.array([[m11, m12], [m21, m22]]), np.array([f1, f2]))
        return np.array([y[2], y[3], acc[0], acc[1]])

    return fun


def bench_simulate(*, baseline_t: float = 0.002, t_end: float = 1.0, rtol: float = 1e-9) -> list[BenchResult]:
    """Wall time per simulated second (paper-fig2, default mu and k_ip, perturbation 1e-5 rad).

    The baseline (lambdify + ``solve_ivp`` RK45, same ``rtol``/``atol``, no
    dense output) runs ``baseline_t`` seconds of simulated time in the same
    process; its wall time is scaled to 1 s (the cost per simulated second is
    constant: the step size is set by the ~1.7 kHz oscillation).
    """
    from scipy.integrate import solve_ivp

    from ..parameters import get_preset
    from ._integrate import default_model, simulate

    params = get_preset("paper-fig2").resolve()
    t0 = time.perf_counter()
    model = default_model()
    simulate(model, params, 0.001)  # load / compile
    warm = time.perf_counter() - t0
    runs: dict[str, Any] = {}

    def ours() -> None:
        runs["jit"] = simulate(model, params, t_end, rtol=rtol, perturbation=[1e-5, 0.0])  # as the baseline

    t_jit = best_time(ours, repeat=3) / t_end
    tr = runs["jit"]
    t_scipy_dop = best_time(lambda: simulate(model, params, 0.1, rtol=rtol, method="DOP853"), repeat=1) / 0.1
    t_build = time.perf_counter()
    fun = lambdify_rhs(params)
    t_build = time.perf_counter() - t_build
    y0 = np.array([1e-5, 0.0, 0.0, 0.0])
    out: dict[str, Any] = {}

    def base() -> None:
        out["sol"] = solve_ivp(fun, (0.0, baseline_t), y0, method="RK45", rtol=rtol, atol=tr.atol)

    t_base = best_time(base, repeat=1) / baseline_t
    return [
        BenchResult(
            "simulate: wall time per simulated second (paper-fig2, DOP853-jit)",
            t_jit, "s", t_base, t_base / t_jit,
            {
                "rtol": rtol, "steps_per_s": tr.stats.get("steps"), "rhs_evals_per_s": tr.stats.get("nfev"),
                "output_samples": int(tr.t.size), "first_call_load_compile_s": round(warm, 3),
                "scipy_DOP853_same_jit_rhs_s_per_sim_s": round(t_scipy_dop, 3),
                "baseline": f"sympy lambdify (no cse) RHS + Python Newton for l + solve_ivp RK45, same rtol/atol, "
                f"{baseline_t:g} s simulated and scaled to 1 s ({out['sol'].nfev} RHS calls); "
                f"lambdify build {t_build:.2f} s not included",
                "target": "<= 1 s wall per simulated second and >= 10x the baseline",
            },
        )  # fmt: skip
    ]
