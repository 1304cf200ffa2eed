"""Simulation speed: the compiled simulator vs. straightforward baselines, measured in the same run.

* paper-fig2 (2 DOF) against a SymPy ``lambdify`` right-hand side with ``solve_ivp`` RK45;
* eight-dof (8 DOF) against the built models' former path: the model's generated Python code (the
  unified code generator bound to :mod:`math`), the pads' Newton solve and ``M Qddot = -f`` in NumPy,
  ``solve_ivp`` DOP853 (what ``brakesqueal.builder.simulate`` did before the compiled simulator
  covered every model).

Run by ``make bench`` (``python -m benchmarks``) or directly:
``python benchmarks/bench_simulate.py [--baseline-t SECONDS]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import BenchResult, best_time, emit  # noqa: E402


def lambdify_rhs(params: Any) -> Callable[[float, np.ndarray], np.ndarray]:
    """The paper model's RHS built the straightforward way: SymPy ``lambdify`` without CSE.

    From the same equations as the kernels (:func:`~brakesqueal.symbolic.assemble.build_equations`,
    quasi-static pads ``ldot = 0``): the pads' ``l`` is solved by Newton iterations (warm-started)
    in Python, ``q_mddot = -M^{-1} R(q_mddot = 0)`` with NumPy.
    """
    import sympy as sp

    from brakesqueal.analysis.equilibrium import as_parameters
    from brakesqueal.symbolic.assemble import build_equations

    params = as_parameters(params)
    eq = build_equations(params.model)
    n, m = eq.n, eq.m
    quasi = {s: 0 for s in eq.dL}
    dd0 = {s: 0 for s in eq.ddQ}
    R = [eq.R[i].subs(quasi) for i in range(n)]
    mass = [R[i].diff(eq.ddQ[j]) for i in range(n) for j in range(n)] + [R[i].subs(dd0) for i in range(n)]
    G = [eq.G[j].subs(quasi) for j in range(m)]
    g = G + [G[j].diff(eq.L[j]) for j in range(m)]
    ys = [sp.Symbol(str(s)) for s in (*eq.Q, *eq.dQ)]
    ls = [sp.Symbol(str(s)) for s in eq.L]
    ps = [sp.Symbol(str(s)) for s in eq.params]
    mfun = sp.lambdify((ys, ls, ps), [sp.sympify(str(e)) for e in mass], "numpy")
    gfun = sp.lambdify((ys, ls, ps), [sp.sympify(str(e)) for e in g], "numpy")
    p = tuple(map(float, params.vector()))
    lbuf = np.zeros(m)

    def fun(t: float, y: np.ndarray) -> np.ndarray:
        yy = tuple(y)
        for _ in range(30):
            v = gfun(yy, tuple(lbuf), p)
            d = np.array(v[:m]) / np.array(v[m:])
            lbuf[:] -= d
            if np.all(np.abs(d) <= 1e-13 * np.abs(lbuf) + 1e-300):
                break
        v = mfun(yy, tuple(lbuf), p)
        acc = -np.linalg.solve(np.array(v[: n * n]).reshape(n, n), np.array(v[n * n:]))
        return np.concatenate([y[n:], acc])

    return fun


def builder_rhs(params: Any) -> tuple[Callable[[float, np.ndarray], np.ndarray], np.ndarray]:
    """The former built-model path: ``f(t, y)`` on the generated Python code, and the silent state.

    As ``brakesqueal.builder.simulate`` did: ``R`` and its Jacobian from the
    model's generated code (:func:`~brakesqueal.codegen.compile_model`, bound
    to :mod:`math`), the quasi-static pads' ``L`` by Newton's method in NumPy,
    ``M = dR/dQddot`` from the Jacobian, ``Qddot = -M^{-1} R(Qddot = 0)``.
    """
    from brakesqueal import silent_motion
    from brakesqueal.analysis.equilibrium import as_parameters
    from brakesqueal.codegen import compile_model

    params = as_parameters(params)
    cm = compile_model(params.model)
    n, m = cm.n, cm.m
    p = list(map(float, params.vector()))
    sm = silent_motion(params)
    L = np.array(sm.l0, dtype=float)
    zeros = [0.0] * n

    def solve_L(Q: np.ndarray, dQ: np.ndarray) -> np.ndarray:
        nonlocal L
        for _ in range(20):
            x = [*Q, *dQ, *zeros, *L, *([0.0] * m)]
            gv = np.asarray(cm.residuals(x, p)[n:])
            GL = cm.jacobian_matrix(x, p)[n:, 3 * n:3 * n + m]
            step = np.linalg.solve(GL, -gv)
            L = L + step
            if np.all(np.abs(step) <= 1e-14 * (np.abs(L) + 1e-12)):
                break
        return L

    def fun(t: float, y: np.ndarray) -> np.ndarray:
        Q, dQ = y[:n], y[n:]
        Lv = solve_L(Q, dQ) if m else L
        x = [*Q, *dQ, *zeros, *Lv, *([0.0] * m)]
        R0 = np.asarray(cm.residuals(x, p)[:n])
        M = cm.jacobian_matrix(x, p)[:n, 2 * n:3 * n]
        return np.concatenate([dQ, -np.linalg.solve(M, R0)])

    return fun, np.concatenate([sm.q0, np.zeros(n)])


def _compiled_run(model_name: str, params: Any, t_end: float, rtol: float, **kw: Any) -> tuple[float, Any, float]:
    from brakesqueal import simulation_model
    from brakesqueal.simulation import simulate

    t0 = time.perf_counter()
    model = simulation_model(model_name)
    simulate(model, params, 0.001, **kw)  # load / compile
    warm = time.perf_counter() - t0
    runs: dict[str, Any] = {}

    def ours() -> None:
        runs["jit"] = simulate(model, params, t_end, rtol=rtol, **kw)

    return best_time(ours, repeat=3) / t_end, runs["jit"], warm


def bench_simulate(*, baseline_t: float = 0.002, t_end: float = 1.0, rtol: float = 1e-9,
                   builder_t: float = 0.005) -> list[BenchResult]:
    """Wall time per simulated second: paper-fig2 (2 DOF) and eight-dof (8 DOF), each against its baseline.

    Parameters
    ----------
    baseline_t : float, optional
        Simulated time [s] of the lambdify baseline (2 DOF), scaled to 1 s.
    t_end : float, optional
        Simulated time [s] of the compiled runs (best of 3).
    rtol : float, optional
        Relative tolerance of every run (``atol`` as the compiled run's default).
    builder_t : float, optional
        Simulated time [s] of the former built-model path (8 DOF), scaled to 1 s.

    Returns
    -------
    list of BenchResult
        The cost per simulated second is constant (the step size is set by
        the squeal oscillation), so the baselines' short runs are scaled.
    """
    from scipy.integrate import solve_ivp

    from brakesqueal.model import get_preset, resolve_parameters
    from brakesqueal import simulation_model
    from brakesqueal.simulation import simulate

    params = get_preset("paper-fig2").resolve()
    t_jit, tr, warm = _compiled_run("paper", params, t_end, rtol, perturbation=[1e-5, 0.0])  # as the baseline
    model = simulation_model("paper")
    t_scipy_dop = best_time(lambda: simulate(model, params, 0.1, rtol=rtol, method="DOP853"), repeat=1) / 0.1
    t_build = time.perf_counter()
    fun = lambdify_rhs(params)
    t_build = time.perf_counter() - t_build
    y0 = np.array([1e-5, 0.0, 0.0, 0.0])
    out: dict[str, Any] = {}

    def base() -> None:
        out["sol"] = solve_ivp(fun, (0.0, baseline_t), y0, method="RK45", rtol=rtol, atol=tr.atol)

    t_base = best_time(base, repeat=1) / baseline_t
    # eight-dof: compiled vs the former built-model path (same start, tolerances and method family)
    p8 = resolve_parameters("eight-dof")
    t8, tr8, warm8 = _compiled_run("eight-dof", p8, t_end, rtol)
    fun8, _ = builder_rhs(p8)
    y8 = tr8.y_start
    out8: dict[str, Any] = {}

    def base8() -> None:
        out8["sol"] = solve_ivp(fun8, (0.0, builder_t), y8, method="DOP853", rtol=rtol, atol=tr8.atol)

    t_base8 = best_time(base8, repeat=1) / builder_t
    ref8 = simulate(simulation_model("eight-dof"), p8, builder_t, rtol=rtol, sample_rate=1.0 / builder_t)
    dev8 = float(np.abs(out8["sol"].y[:, -1] - ref8.y[-1]).max() / np.abs(ref8.y[-1] - ref8.silent_state).max())
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
        ),
        BenchResult(
            "simulate: wall time per simulated second (eight-dof, DOP853-jit)",
            t8, "s", t_base8, t_base8 / t8,
            {
                "rtol": rtol, "simulated_s_per_wall_s": round(1.0 / t8, 2),
                "steps_per_s": tr8.stats.get("steps"), "rhs_evals_per_s": tr8.stats.get("nfev"),
                "status": tr8.status, "first_call_load_compile_s": round(warm8, 3),
                "baseline": f"the former built-model path (generated Python code, NumPy Newton and mass solve, "
                f"solve_ivp DOP853), same start, rtol and atol, {builder_t:g} s simulated and scaled to 1 s "
                f"({out8['sol'].nfev} RHS calls; its end state differs from the compiled run's by "
                f"{dev8:.1e} of the deviation)",
                "target": ">= 1 simulated second per wall second",
            },
        ),
    ]  # fmt: skip


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--baseline-t", type=float, default=0.002,
                    help="simulated time of the (slow) lambdify baseline run [s]")
    emit(bench_simulate(baseline_t=ap.parse_args().baseline_t))
