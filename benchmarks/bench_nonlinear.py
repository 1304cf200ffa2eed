r"""Benchmarks of the nonlinear machinery on a 4-state, 2-DOF friction-type (mode-coupling) oscillator.

The test system (dimensionless, the structure of the paper's 2-DOF model linearised at the silent
motion plus cubic terms):

.. math::

   \ddot q + C \dot q + K(p) q + k_n q^3 + d_n q^2 \dot q = 0,\qquad
   K(p) = \begin{pmatrix} k_1 & p \\ -p & k_2 \end{pmatrix},\quad C = \mathrm{diag}(c_1, c_2)

(cubic terms componentwise); ``p`` plays the friction coefficient times the contact stiffness
(circulatory coupling).  State ``x = (q1, q2, dq1, dq2)``; exact ``B``, ``C`` are given.

Measured (``python benchmarks/bench_nonlinear.py [--points N] [--brute-points M]``, run by
``make bench``): ``first_lyapunov`` warm (exact and finite-difference forms), a 200-point cycle branch
with :class:`~brakesqueal.nonlinear.CompiledFlow` and with :class:`~brakesqueal.nonlinear.ScipyFlow`,
and the brute-force baseline: long simulations (same compiled integrator, no sensitivities) at
parameter values of the branch until the peak of ``q1`` changes by less than ``1e-6`` per period,
timed on a subset of the branch's points and scaled to 200 points.  The parameter range is
squeal-like: the linear growth rate at its end is 1 % of the angular frequency, so near onset
the transients of the simulations decay slowly, as they do for brake squeal.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import BenchResult, best_time, emit  # noqa: E402

from brakesqueal.nonlinear import SmoothSystem  # noqa: E402

K1, K2, C1, C2, KN, DN = 1.0, 1.5, 0.02, 0.02, 0.5, 0.3


def _period_diff(branch: Any, d: Any, n_pts: int) -> float | None:
    """Largest relative period difference of two branches of equal length (None if their lengths differ)."""
    if branch.sizes["point"] != n_pts:
        return None
    return float(np.max(np.abs(branch["period"].values / d["period"].values[:n_pts] - 1)))


def _f(x: np.ndarray, p: float) -> np.ndarray:
    q, v = x[:2], x[2:]
    acc = -np.array([K1 * q[0] + p * q[1], -p * q[0] + K2 * q[1]]) - np.array([C1, C2]) * v - KN * q**3 - DN * q**2 * v
    return np.concatenate([v, acc])


def _jac(x: np.ndarray, p: float) -> np.ndarray:
    q, v = x[:2], x[2:]
    J = np.zeros((4, 4))
    J[0, 2] = J[1, 3] = 1.0
    J[2:, :2] = -np.array([[K1, p], [-p, K2]]) - np.diag(3 * KN * q**2 + 2 * DN * q * v)
    J[2:, 2:] = -np.diag([C1, C2]) - np.diag(DN * q**2)
    return J


def _dfdp(x: np.ndarray, p: float) -> np.ndarray:
    return np.array([0.0, 0.0, -x[1], x[0]])


def _jac_p(x: np.ndarray, p: float) -> np.ndarray:
    J = np.zeros((4, 4))
    J[2, 1], J[3, 0] = -1.0, 1.0
    return J


def _B(x: np.ndarray, p: float, u: np.ndarray, w: np.ndarray) -> np.ndarray:
    q, v = x[:2], x[2:]
    out = np.zeros(4, dtype=np.result_type(u, w, float))
    out[2:] = -((6 * KN * q + 2 * DN * v) * u[:2] * w[:2] + 2 * DN * q * (u[:2] * w[2:] + u[2:] * w[:2]))
    return out


def _C(x: np.ndarray, p: float, u: np.ndarray, w: np.ndarray, z: np.ndarray) -> np.ndarray:
    out = np.zeros(4, dtype=np.result_type(u, w, z, float))
    uq, wq, zq = u[:2], w[:2], z[:2]
    out[2:] = -(6 * KN * uq * wq * zq + 2 * DN * (uq * wq * z[2:] + uq * w[2:] * zq + u[2:] * wq * zq))
    return out


def _kernels() -> tuple[Any, Any, Any]:
    import numba

    from brakesqueal.nonlinear.compiled import F_SIGNATURE, JAC_SIGNATURE

    @numba.njit(F_SIGNATURE, cache=True)
    def f(x, p, th, out):  # pragma: no cover - compiled
        out[0] = x[2]
        out[1] = x[3]
        out[2] = -(K1 * x[0] + p * x[1]) - C1 * x[2] - KN * x[0] ** 3 - DN * x[0] ** 2 * x[2]
        out[3] = -(-p * x[0] + K2 * x[1]) - C2 * x[3] - KN * x[1] ** 3 - DN * x[1] ** 2 * x[3]

    @numba.njit(JAC_SIGNATURE, cache=True)
    def jac(x, p, th, out):  # pragma: no cover - compiled
        out[:, :] = 0.0
        out[0, 2] = 1.0
        out[1, 3] = 1.0
        out[2, 0] = -K1 - 3 * KN * x[0] ** 2 - 2 * DN * x[0] * x[2]
        out[2, 1] = -p
        out[3, 0] = p
        out[3, 1] = -K2 - 3 * KN * x[1] ** 2 - 2 * DN * x[1] * x[3]
        out[2, 2] = -C1 - DN * x[0] ** 2
        out[3, 3] = -C2 - DN * x[1] ** 2

    @numba.njit(F_SIGNATURE, cache=True)
    def dfdp(x, p, th, out):  # pragma: no cover - compiled
        out[0] = 0.0
        out[1] = 0.0
        out[2] = -x[1]
        out[3] = x[0]

    from brakesqueal.codegen.cache import guard_numba_caches

    guard_numba_caches([f, jac, dfdp])  # a damaged or unwritable numba cache file is recompiled, never an error
    return f, jac, dfdp


def benchmark_system(compiled: bool = False, exact: bool = True) -> SmoothSystem:
    """The 4-state benchmark system (module docstring), optionally backed by numba kernels.

    Parameters
    ----------
    compiled : bool
        Build it with :func:`~.compiled.compiled_system` (needed by :class:`~.compiled.CompiledFlow`).
    exact : bool
        Give the exact ``B``, ``C`` (else the finite-difference fallback is used).

    Returns
    -------
    SmoothSystem
        State ``(q1, q2, dq1, dq2)``, parameter ``p``.
    """
    extra: dict[str, Any] = {"jac_p": _jac_p, "state_names": ("q1", "q2", "dq1", "dq2"), "parameter_name": "p"}
    if exact:
        extra.update(B=_B, C=_C)
    if compiled:
        from brakesqueal.nonlinear import compiled_system

        return compiled_system(*_kernels(), 4, **extra)
    return SmoothSystem(f=_f, jac=_jac, n=4, dfdp=_dfdp, **extra)


def _hopf_guess() -> float:
    """Parameter of the Hopf point of the linear part (bisection on the largest real part)."""
    lo, hi = 0.0, 2.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if np.max(np.linalg.eigvals(_jac(np.zeros(4), mid)).real) > 0:
            hi = mid
        else:
            lo = mid
    return hi


def _peak(samples: np.ndarray, t: np.ndarray) -> tuple[float, float]:
    """Maximum of sampled data and its time, refined by a parabola through the three samples around it
    (the time is NaN when the maximum sits at the first or last sample)."""
    i0 = int(np.argmax(samples))
    i = int(np.clip(i0, 1, samples.size - 2))
    ym, y0, yp = samples[i - 1], samples[i], samples[i + 1]
    den = ym - 2 * y0 + yp
    d = 0.5 * (ym - yp) / den if den != 0 else 0.0
    tp = float(t[i] + d * (t[1] - t[0])) if i == i0 else float("nan")
    return float(y0 - 0.25 * (ym - yp) * d), tp


def _brute_force(flow: Any, hopf: Any, ps: np.ndarray, tol: float = 1e-6,
                 max_periods: int = 50000) -> tuple[np.ndarray, np.ndarray, int, int]:  # fmt: skip
    """Peak q1 and period at each ``p`` by simulating period after period until the peak settles.

    Each window is one estimated period (256 samples); the peak is refined by a parabola and the period
    re-estimated from the times of consecutive peaks.  Returns ``(peaks, periods, total periods,
    number of values that hit max_periods)``.
    """
    x = hopf.cycle_guess(ps[0]).x[0]
    T = hopf.period(ps[0])
    peaks, periods = [], []
    total = capped = 0
    t_glob = 0.0
    for p in ps:
        prev, t_prev, a = np.inf, None, np.nan
        for k in range(max_periods):
            fr = flow(x, T, float(p), sensitivities=False, n_samples=256)
            x = fr.x
            a, tp = _peak(fr.x_samples[:, 0], fr.t_samples)
            tp += t_glob
            t_glob += T
            total += 1
            if t_prev is not None and np.isfinite(tp) and 0.5 * T < tp - t_prev < 1.5 * T:
                T = tp - t_prev
            t_prev = tp if np.isfinite(tp) else None
            if abs(a - prev) <= tol * abs(a):
                break
            prev = a
        else:
            capped += 1
        peaks.append(a)
        periods.append(T)
    return np.asarray(peaks), np.asarray(periods), total, capped


def bench_nonlinear(*, points: int = 200, brute_points: int = 10) -> list[BenchResult]:
    """Timings of ``first_lyapunov`` and of a ``points``-point cycle branch, against brute force.

    Parameters
    ----------
    points : int
        Points of the continued branch (default 200).
    brute_points : int
        Parameter values simulated by the brute-force baseline (its time is scaled to ``points``).

    Returns
    -------
    list of BenchResult
        Headline: the compiled 200-point branch vs brute force; then the SciPy-flow branch and ``l1``.
    """
    from brakesqueal.nonlinear import CompiledFlow, ScipyFlow, continue_cycles, first_lyapunov

    p_h = _hopf_guess()
    sc = benchmark_system(compiled=True)
    t0 = time.perf_counter()
    flow_c = CompiledFlow(sc)
    flow_c(np.full(4, 0.1), 1.0, p_h)  # load/compile the kernels
    t_load = time.perf_counter() - t0
    x0 = np.zeros(4)
    hopf = first_lyapunov(sc, x0, p_h)
    t_l1 = best_time(lambda: first_lyapunov(sc, x0, hopf.p0), repeat=20)
    sfd = benchmark_system(exact=False)
    t_l1_fd = best_time(lambda: first_lyapunov(sfd, x0, hopf.p0), repeat=20)
    h_fd = first_lyapunov(sfd, x0, hopf.p0)
    # a squeal-like range: the linear growth rate at its end is 1 % of the angular frequency
    width = 0.01 * hopf.omega0 / abs(hopf.dRe_lambda_dp)
    p_range = (hopf.p0, hopf.p0 + width) if hopf.side > 0 else (hopf.p0 - width, hopf.p0)
    kw = {"max_points": points, "ds_max": 0.005, "n_samples": 256}
    t0 = time.perf_counter()
    br_c = continue_cycles(sc, hopf, p_range, flow=flow_c, **kw)
    t_c = time.perf_counter() - t0
    t0 = time.perf_counter()
    br_s = continue_cycles(sc, hopf, p_range, flow=ScipyFlow(sc), **kw)
    t_s = time.perf_counter() - t0
    d = br_c.data
    stable = d["stable"].values & (d["label"].values == "")
    p_st = d["p"].values[stable]
    # the same parameter values as the branch (a subset evenly spread over its points, Hopf excluded)
    ps = p_st[np.unique(np.linspace(1, p_st.size - 1, brute_points).round().astype(int))]
    t0 = time.perf_counter()
    peaks, periods_bf, n_periods, capped = _brute_force(flow_c, hopf, ps)
    t_bf = time.perf_counter() - t0
    t_bf_scaled = t_bf * points / ps.size
    # the branch's peak of q1 at the same p: interpolate between the stored orbits' refined peaks
    orb = d["orbit"].values[:, :, 0]
    bpk = np.array([_peak(o, np.arange(o.size) / o.size)[0] for o in orb])
    a_cont = np.interp(ps, d["p"].values[stable], bpk[stable])
    agree = float(np.max(np.abs(peaks / a_cont - 1)))
    agree_T = float(np.max(np.abs(periods_bf / np.interp(ps, d["p"].values[stable], d["period"].values[stable]) - 1)))
    n_pts = int(d.sizes["point"])
    return [
        BenchResult(
            f"cycle branch, {n_pts} points, 4 states (CompiledFlow)", t_c, "s", t_bf_scaled, t_bf_scaled / t_c,
            {"baseline": f"brute force: long compiled simulations until the q1 peak settles to 1e-6 per period, "
                         f"{ps.size} of the branch's stable parameter values ({n_periods} periods, "
                         f"{capped} capped at 50000) "
                         f"scaled to {points}",
             "brute_force_s": round(t_bf, 3), "brute_force_vs_branch_peak_max_rel_diff": agree,
             "brute_force_vs_branch_period_max_rel_diff": agree_T, "p_range_of_branch": [float(d["p"].values.min()),
                                                                                         float(d["p"].values.max())],
             "special_points": [s.kind for s in br_c.special], "status": br_c.status,
             "kernel_load_s": round(t_load, 3), "target_s": 20.0},
        ),
        BenchResult(
            f"cycle branch, {int(br_s.data.sizes['point'])} points, 4 states (ScipyFlow, Python RHS)", t_s, "s",
            t_bf_scaled, t_bf_scaled / t_s,
            {"same_branch_max_rel_diff_vs_compiled": _period_diff(br_s.data, d, n_pts)},
        ),
        BenchResult(
            "first_lyapunov at a Hopf point (exact B, C; warm)", t_l1, "s", t_l1_fd, t_l1_fd / t_l1,
            {"baseline": "same with finite-difference B, C", "l1": hopf.l1, "l1_fd": h_fd.l1,
             "l1_error_fd": h_fd.l1_error, "criticality": hopf.criticality, "target_s": 0.05},
        ),
    ]  # fmt: skip


def _branch_diff(old: Any, new: Any, n_pts: int) -> float:
    """Largest relative difference of period, amplitudes and Floquet multipliers over the first ``n_pts`` points."""
    out = 0.0
    for key in ("p", "period", "amplitude", "floquet_re", "floquet_im"):
        a, b = old[key].values[:n_pts], new[key].values[:n_pts]
        top = max(float(np.nanmax(np.abs(a))), 1e-300)
        out = max(out, float(np.nanmax(np.abs(a - b))) / top)
    return out


def bench_paper_model(*, points: int = 200, old_points: int = 20, brute_points: int = 3,
                      ds_max: float = 0.005) -> list[BenchResult]:  # fmt: skip
    """The paper's model (Fig. 3 set, mu = 0.5, rigid pads): l1 at the Hopf point and a limit-cycle branch.

    ``l1`` warm against the issue's target of 50 ms (ratio target / measured).  The branch
    (:func:`~brakesqueal.nonlinear.continue_cycles` on :func:`~brakesqueal.nonlinear.models.model_system`
    over ``Omega`` in [30, 40] with steps up to ``ds_max``) is timed for ``points`` points with the compiled flow
    and the model's generated exact Jacobian (:func:`~brakesqueal.nonlinear.compiled.model_flow`).  Baselines in
    the same process: (1) the previous route, ScipyFlow with the Python exact Jacobian
    (:func:`~brakesqueal.simulation.state_jacobian`), for ``old_points`` points of the same branch scaled to
    ``points`` (and the largest relative difference between the two branches there); (2) brute force: one long
    compiled simulation (``simulate``, from the default start along the leading mode) per parameter value until
    ``10 / sigma`` (``sigma`` the linear growth rate there, capped at 20 s of simulated time), at the
    ``brute_points`` stable branch points farthest from onset (the fastest transients; nearer the onset brute
    force is slower still), scaled to ``points``.  The amplitude it reaches is compared with the branch's (a
    large difference means the baseline had not converged: it is then a lower bound).

    Parameters
    ----------
    points : int
        Points of the timed branch (compiled flow).
    old_points : int
        Points of the same branch by the previous route (ScipyFlow, Python Jacobian).
    brute_points : int
        Parameter values simulated by the brute-force baseline.
    ds_max : float
        Largest continuation step (scaled arclength; small enough that ``points`` points fit in the range).

    Returns
    -------
    list of BenchResult
    """
    import math as _m

    from brakesqueal import Axis, hopf_points, model_flow, model_system, simulate
    from brakesqueal.model import ParameterSpace
    from brakesqueal.nonlinear import ScipyFlow, continue_cycles, first_lyapunov

    space = ParameterSpace.from_preset("paper-fig3", {"mu1": 0.5, "mu2": 0.5, "k_ip": _m.inf})
    hp = hopf_points(space, Axis("Omega", 30.0, 40.0))[0]
    system = model_system(space, "Omega")
    sim = system.simulation_model  # type: ignore[attr-defined]
    y0 = sim.silent(space.resolve({"Omega": hp.value})).y
    first_lyapunov(system, y0, hp.value, refine=False)
    t_l1 = best_time(lambda: first_lyapunov(system, y0, hp.value, refine=False), repeat=5)
    # soft pads (k_ip = 1e6): the normal form of the implicit equations, pads' rates kept (refinement included)
    from brakesqueal import exact_lyapunov

    soft = ParameterSpace.from_preset("paper-fig3", {"mu1": 0.5, "mu2": 0.5, "k_ip": 1e6})
    p_soft = exact_lyapunov(soft, "Omega", 80.0).hopf.p0
    t_ex = best_time(lambda: exact_lyapunov(soft, "Omega", p_soft), repeat=5)
    flow = model_flow(space, "Omega", system=system)
    flow(y0 + 1e-6 * np.abs(y0).max(), 1e-3, hp.value)  # load the compiled kernels
    kw: dict[str, Any] = {"tol": 1e-8, "ds_max": ds_max}
    continue_cycles(system, hp.hopf, (30.0, 40.0), max_points=3, flow=flow, **kw)  # warm (imports, first calls)
    t0 = time.perf_counter()
    br = continue_cycles(system, hp.hopf, (30.0, 40.0), max_points=points, flow=flow, **kw)
    t_br = time.perf_counter() - t0
    d = br.data
    n_pts = int(d.sizes["point"])
    t0 = time.perf_counter()
    br_old = continue_cycles(system, hp.hopf, (30.0, 40.0), max_points=old_points, flow=ScipyFlow(system), **kw)
    t_old = time.perf_counter() - t0
    n_old = int(br_old.data.sizes["point"])
    t_old_scaled = t_old * n_pts / n_old
    diff = _branch_diff(br_old.data, d, min(n_old, n_pts))
    ok = np.flatnonzero(d["stable"].values & (d["label"].values == ""))
    idx = ok[-brute_points:]  # the stable points farthest from onset: the fastest brute-force transients
    t0 = time.perf_counter()
    diffs, sim_s = [], 0.0
    for i in idx:
        p = float(d["p"].values[i])
        params = space.resolve({"Omega": p})
        modes = sim.linear_modes(params)
        sigma = float(modes.eigenvalues[0].real) if modes is not None else 1.0
        t_end = min(10.0 / max(sigma, 1e-9), 20.0)
        sim_s += t_end
        tr = simulate(params, t_end, events="off", sample_rate=200_000.0)
        n_last = int(0.002 * 200_000)
        a_sim = 0.5 * float(np.ptp(tr.y[-n_last:, 0]))
        a_br = 0.5 * float(np.ptp(d["orbit"].values[i][:, 0]))
        diffs.append(abs(a_sim / a_br - 1))
    t_bf = time.perf_counter() - t0
    t_bf_scaled = t_bf * n_pts / max(idx.size, 1)
    return [
        BenchResult(
            f"paper model: {n_pts}-point cycle branch, compiled flow (generated exact Jacobian)", t_br, "s",
            t_old_scaled, t_old_scaled / t_br,
            {"baseline": f"ScipyFlow with the Python exact Jacobian, {n_old} points scaled to {n_pts}",
             "measured_points": n_pts, "old_route_s": round(t_old, 3), "old_route_points": n_old,
             "same_branch_max_rel_diff": diff, "target_s": 20.0, "status": br.status,
             "p_end": float(d["p"].values[-1])},
        ),
        BenchResult(
            f"paper model: {n_pts}-point cycle branch against brute force", t_br, "s", t_bf_scaled,
            t_bf_scaled / t_br,
            {"baseline": f"brute force: one long compiled simulation per parameter value (10/sigma, at most 20 s "
                         f"simulated; {sim_s:.3g} s simulated for {idx.size} values) scaled to {n_pts}",
             "brute_force_s": round(t_bf, 3),
             "brute_force_vs_branch_half_peak_to_peak_max_rel_diff": float(max(diffs)) if diffs else None},
        ),
        BenchResult(
            "paper model: first_lyapunov at the Fig. 3 Hopf point (warm, FD B, C of the exact Jacobian)", t_l1, "s",
            0.05, 0.05 / t_l1, {"baseline": "the issue's target 50 ms", "l1": hp.hopf.l1 if hp.hopf else None},
        ),
        BenchResult(
            "paper model, k_ip = 1e6: exact_lyapunov with the pads' true tangential dynamics (warm, refined)",
            t_ex, "s", 0.05, 0.05 / t_ex, {"baseline": "the issue's target 50 ms"},
        ),
    ]  # fmt: skip


def bench_exact_pads_branch(*, points: int = 200) -> list[BenchResult]:
    """The route ``cycles`` takes by default on the paper's model (soft massless Coulomb pads): harmonic balance.

    Fig. 3 set, ``mu1 = mu2 = 0.5``, ``k_ip = 1e8`` (preset ``paper-fig3``), ``Omega`` in [30, 200]: ``points``
    points of :func:`~brakesqueal.nonlinear.harmonic.harmonic_branch` with Hill's stability, continued past the
    contact loss (``stop_at_contact_loss=False``) so that the count is reached.  Baselines in the same process:
    the same branch without stability (the share of Hill's method) and ``points`` points of the quasi-static pads'
    branch shot with the compiled flow (``squeal_branch``, the route ``cycles`` took before on this model).

    Parameters
    ----------
    points : int
        Points of each branch.

    Returns
    -------
    list of BenchResult
    """
    from brakesqueal import Axis, harmonic_branch, squeal_branch
    from brakesqueal.model import ParameterSpace

    space = ParameterSpace.from_preset("paper-fig3", {"mu1": 0.5, "mu2": 0.5})
    axis = Axis("Omega", 30.0, 200.0)
    harmonic_branch(space, axis, max_points=3)  # warm: compiled code, imports
    squeal_branch(space, axis, max_points=3)
    t0 = time.perf_counter()
    hb = harmonic_branch(space, axis, max_points=points, stop_at_contact_loss=False)
    t_hb = time.perf_counter() - t0
    t0 = time.perf_counter()
    harmonic_branch(space, axis, max_points=points, stop_at_contact_loss=False, stability=False)
    t_nostab = time.perf_counter() - t0
    t0 = time.perf_counter()
    qs = squeal_branch(space, axis, max_points=points)  # cycles' settings
    t_qs = time.perf_counter() - t0
    n_qs = int(qs.data.sizes["point"])
    return [
        BenchResult(
            f"paper model (k_ip = 1e8): {len(hb.points)}-point branch, exact pads (harmonic balance, Hill stability)",
            t_hb, "s", t_nostab, t_nostab / t_hb,
            {"baseline": "the same branch without stability (Newton and continuation only)",
             "target_s": 20.0, "p_end": hb.points[-1].p, "contact_loss": hb.contact_loss,
             "largest_harmonics": max(pt.harmonics for pt in hb.points)},
        ),
        BenchResult(
            "paper model (k_ip = 1e8): exact-pads branch against the quasi-static pads' shot branch",
            t_hb, "s", t_qs * len(hb.points) / max(n_qs, 1), t_qs * len(hb.points) / max(n_qs, 1) / t_hb,
            {"baseline": f"squeal_branch (quasi-static pads, compiled flow), {n_qs} points scaled to "
                         f"{len(hb.points)}", "quasi_static_s": round(t_qs, 3)},
        ),
    ]  # fmt: skip


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--points", type=int, default=200, help="points of the continued branch")
    ap.add_argument("--brute-points", type=int, default=10, help="parameter values simulated by the baseline")
    ap.add_argument("--paper-points", type=int, default=200, help="points of the paper-model branch (compiled flow)")
    ap.add_argument("--paper-old-points", type=int, default=20,
                    help="points of the same branch by the previous route (ScipyFlow, Python Jacobian), scaled")
    a = ap.parse_args()
    for opt, v in (("--paper-points", a.paper_points), ("--paper-old-points", a.paper_old_points)):
        if not 2 <= v <= 10_000:
            ap.error(f"{opt} must be in [2, 10000]; got {v}")
    emit(bench_nonlinear(points=a.points, brute_points=a.brute_points)
         + bench_paper_model(points=a.paper_points, old_points=a.paper_old_points)
         + bench_exact_pads_branch(points=a.paper_points))
