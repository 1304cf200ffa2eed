r"""The simulation entry point :func:`simulate` and the model object it integrates."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from types import ModuleType
from typing import Any, Callable, Literal, Sequence

import numpy as np

from ..errors import BrakesquealError, ParameterError, SilentMotionError
from ..parameters import Parameters
from .estimate import LinearModes, linear_modes
from .trajectory import EstimationRecord, Trajectory

__all__ = ["METHODS", "POINTS_PER_PERIOD", "START_AMPLITUDE", "SimulationModel", "default_model", "simulate"]

#: Integration methods: the compiled DOP853 (default) and SciPy's ``solve_ivp`` methods.
METHODS: tuple[str, ...] = ("DOP853-jit", "DOP853", "RK45", "RK23", "Radau", "BDF", "LSODA")
#: Samples per period of the highest linear frequency in the estimation record (summary numbers).
POINTS_PER_PERIOD = 20
#: Largest tilt deviation [rad] of the default start (along the leading mode).
START_AMPLITUDE = 1e-5
EventMode = Literal["stop", "continue", "off"]
_EVENT_NAMES = ("contact-loss-pad1", "contact-loss-pad2", "sliding-reversal-pad1", "sliding-reversal-pad2")


@dataclass(frozen=True)
class SimulationModel:
    """A model :func:`simulate` can integrate: the compiled 2-DOF wobbling-disk model.

    Attributes
    ----------
    name : str
        Identifier (``"general-2dof"``).
    kernels : module
        numba-compiled functions ``rhs(y, l, p, out)``, ``solve_l``,
        ``event_values``, ``post_process`` and the integrator ``dop853``
        (see :mod:`brakesqueal.simulation._kernels`).
    state_names : tuple of str
        ``("q1", "q2", "dq1", "dq2")`` [rad, rad/s].
    use_cache : bool
        Whether the silent motion may use the on-disk code cache.
    """

    name: str
    kernels: ModuleType
    state_names: tuple[str, ...] = ("q1", "q2", "dq1", "dq2")
    use_cache: bool = True

    def parameter_vector(self, params: Parameters) -> np.ndarray:
        """Parameters in the kernels' order (compliances ``1/k_ip``)."""
        from ..analysis.equilibrium import parameter_vector

        return np.asarray(parameter_vector(params), dtype=float)

    def silent(self, params: Parameters) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(y_silent, l_silent, v_r_silent (6,))`` of the silent motion (eq. 46)."""
        from ..analysis.equilibrium import silent_motion
        from ..numeric.compiled import compiled_model

        sm = silent_motion(params, model=compiled_model(use_cache=self.use_cache))
        y = np.array([sm.q_m0[0], sm.q_m0[1], 0.0, 0.0])
        l = sm.l0.astype(float).copy()
        c = np.asarray(self.kernels.contact(y, l, self.parameter_vector(params)))
        return y, l, np.concatenate([c[1:4], c[7:10]])

    def linear_modes(self, params: Parameters) -> LinearModes:
        """Eigenvalues and left/right eigenvectors of the linearization's state matrix (eq. 47).

        The state matrix acts on ``(q - q_m0, dq)``, the simulated state's
        deviation from the silent motion.
        """
        from ..analysis.linear import linearize

        return linear_modes(linearize(params, pad_rates="quasi-static").A)  # the simulated pads are quasi-static

    def rhs(self, params: Parameters) -> Callable[[float, np.ndarray], np.ndarray]:
        """``f(t, y)`` for SciPy (solves the pad deformations on the way, warm-started)."""
        p = self.parameter_vector(params)
        lbuf = np.zeros(2)
        k = self.kernels

        def fun(t: float, y: np.ndarray) -> np.ndarray:
            out = np.empty(4)
            k.rhs(np.ascontiguousarray(y, dtype=float), lbuf, p, out)
            return out

        return fun


def default_model(use_cache: bool = True) -> SimulationModel:
    """The general 2-DOF model of the paper (eq. 44 with quasi-static pads).

    Parameters
    ----------
    use_cache : bool, optional
        Keep the generated kernel source in the package cache (see
        :mod:`brakesqueal.numeric.cache`), where numba also caches its machine
        code (default ``True``).  ``False`` generates and compiles in memory
        and writes no file.

    Returns
    -------
    SimulationModel
        The model ``"general-2dof"`` with its numba-compiled kernels, ready
        for :func:`simulate`.
    """
    from ._kernels import load_kernels

    return SimulationModel(name="general-2dof", kernels=load_kernels(use_cache), use_cache=use_cache)


def _check_tolerances(rtol: float, atol: Any, scale_rate: float) -> np.ndarray:
    if not (isinstance(rtol, (int, float)) and math.isfinite(rtol) and 1e-13 <= rtol <= 1e-2):
        raise ParameterError(f"The option 'rtol' must be in [1e-13, 1e-2]; got {rtol!r}")
    if atol is None:
        return rtol * 1e-6 * np.array([1.0, 1.0, scale_rate, scale_rate])
    a = np.broadcast_to(np.asarray(atol, dtype=float), (4,)).copy()
    if not np.all(np.isfinite(a)) or np.any(a <= 0) or np.any(a > 1.0):
        raise ParameterError(f"The option 'atol' must be in (0, 1] (scalar or 4 values); got {atol!r}")
    return a


def _initial_state(
    x0: Any, perturbation: Any, y_s: np.ndarray, modes: LinearModes | None
) -> tuple[np.ndarray, str]:
    """Initial state and a description of it (``start`` of the trajectory)."""
    if x0 is not None and perturbation is not None:
        raise ParameterError("give either x0 (absolute initial state) or perturbation, not both")
    if x0 is not None:
        v = np.asarray(x0, dtype=float).ravel()
        if v.size != 4:
            raise ParameterError(f"The initial state x0 must have 4 values (q1, q2, dq1, dq2); got {v.size}")
        y0, start = v, "x0 (absolute state)"
    elif perturbation is None and modes is not None:
        y0 = y_s + modes.start_vector(START_AMPLITUDE)
        start = f"leading mode, real part of its eigenvector, max tilt deviation {START_AMPLITUDE:g} rad"
    else:
        d = np.asarray((START_AMPLITUDE, 0.0) if perturbation is None else perturbation, dtype=float).ravel()
        if d.size not in (2, 4):
            raise ParameterError(
                f"The perturbation must have 2 (dq1, dq2) or 4 values (dq1, dq2, dq1dot, dq2dot); got {d.size}"
            )
        y0 = y_s + np.concatenate([d, np.zeros(4 - d.size)])
        start = "perturbation of the silent motion"
    if not np.all(np.isfinite(y0)):
        raise ParameterError(f"The initial state must be finite; got {y0.tolist()}")
    if np.any(np.abs(y0[:2]) >= 0.5 * math.pi):
        raise ParameterError(f"The initial tilt angles must be in (-pi/2, pi/2); got {y0[:2].tolist()}")
    return y0, start


def estimation_rate(modes: LinearModes | None, duration: float) -> float:
    """Sampling rate [Hz] of the estimation record: ``POINTS_PER_PERIOD`` per period of the fastest mode.

    The "frequency" of a mode is ``|lambda| / 2 pi`` (so that a real, fast
    eigenvalue is resolved too); at least 64 samples cover ``duration``.
    Without a linear model the rate is 64 samples over the run.
    """
    fmax = float(np.abs(modes.eigenvalues).max()) / (2 * math.pi) if modes is not None else 0.0
    return max(POINTS_PER_PERIOD * fmax, 64.0 / duration)


def simulate(
    model: SimulationModel | None,
    params: Parameters,
    t_span: float | Sequence[float] = 0.5,
    x0: Sequence[float] | np.ndarray | None = None,
    *,
    perturbation: Sequence[float] | np.ndarray | None = None,
    method: str = "DOP853-jit",
    rtol: float = 1e-9,
    atol: float | Sequence[float] | None = None,
    sample_rate: float = 44100.0,
    events: EventMode = "stop",
    max_step: float = math.inf,
    max_steps: int = 50_000_000,
    progress: Callable[[float], None] | None = None,
    estimate_samples: int = 65536,
) -> Trajectory:
    r"""Integrate the nonlinear 2-DOF equations (44) of the wobbling disk.

    Parameters
    ----------
    model : SimulationModel or None
        The model; ``None`` is :func:`default_model` (the paper's general model).
    params : Parameters
        Model parameters.
    t_span : float or (float, float)
        End time ``t_end`` [s] (start 0) or ``(t0, t_end)``; ``t_end > t0``.
    x0 : array_like, shape (4,), optional
        Absolute initial state ``(q1, q2, dq1, dq2)`` [rad, rad/s].
    perturbation : array_like, shape (2,) or (4,), optional
        Initial deviation from the silent motion ``q_m0`` (rates zero if two
        values).  Default when neither is given: along the leading mode of
        the linearization, ``x(0) = a Re(v_0)`` with ``v_0`` its right
        eigenvector scaled so that the largest tilt component is 1 and
        ``a = START_AMPLITUDE = 1e-5`` rad (a single mode, no beating).
    method : str
        ``"DOP853-jit"`` (compiled Dormand–Prince 8(5,3), default) or one of
        SciPy's ``solve_ivp`` methods ``"DOP853", "RK45", "RK23", "Radau",
        "BDF", "LSODA"`` (same RHS, called from Python; slower).
    rtol : float
        Relative tolerance, in ``[1e-13, 1e-2]``.
    atol : float or array_like (4,), optional
        Absolute tolerance(s) in ``(0, 1]``; default ``1e-6 rtol (1, 1, w, w)``
        with ``w = sqrt(k_t/Theta)`` [rad, rad/s].
    sample_rate : float
        Output samples per second [Hz] (uniform grid, dense output) of
        :attr:`Trajectory.t` / :attr:`Trajectory.y` (NetCDF, WAV, plot).  The
        summary numbers do not use this grid but the estimation record
        (``estimate_samples``).
    events : {"stop", "continue", "off"}
        ``"stop"`` ends the run at the first contact loss (``F_n <= 0``) or
        sliding reversal (``v_r . v_r0 <= 0``, ``v_r0`` the silent-motion
        sliding velocity of that pad); ``"continue"`` records the event times
        and integrates on with the same equations (documented model: bilateral
        contact, friction direction ``v_r/|v_r|``); ``"off"`` ignores them.
    max_step : float
        Largest step [s].
    max_steps : int
        Step budget (compiled method); exceeding it ends the run with status
        ``"failed"``.
    progress : callable, optional
        Called with the fraction done (0..1) while integrating.
    estimate_samples : int
        Length of the estimation record (default 65536): the integrator's
        dense output at ``POINTS_PER_PERIOD = 20`` samples per period of the
        fastest linear mode (:func:`estimation_rate`), of which the last
        ``estimate_samples`` are kept (a ring buffer, so memory stays bounded
        for long runs).  :attr:`Trajectory.summary` is computed from it.

    Returns
    -------
    Trajectory
        Status, message, samples and summary numbers; the partial trajectory
        is kept when the run stops early.

    Raises
    ------
    ParameterError
        Bad options or initial state (non-finite, ``t_end <= t0``, tolerances
        out of range, a pad out of contact at the initial state).
    SilentMotionError
        If the silent motion does not exist (needed for the reference state).

    Notes
    -----
    The pads are massless and quasi-static: ``ldot := 0`` in the relative
    velocities and normal-force rates, and ``l`` follows ``(q, qdot)`` through
    ``g(q, qdot, l, ldot=0) = 0`` (Newton from the previous ``l``), exactly
    as in the linearization.
    """
    model = model or default_model()
    if method not in METHODS:
        raise ParameterError(f"The option 'method' must be one of {', '.join(METHODS)}; got {method!r}")
    if events not in ("stop", "continue", "off"):
        raise ParameterError(f"The option 'events' must be one of stop, continue, off; got {events!r}")
    if np.ndim(t_span) == 0:
        t0, t1 = 0.0, float(t_span)  # type: ignore[arg-type]
    else:
        t0, t1 = (float(v) for v in t_span)  # type: ignore[union-attr]
    if not (math.isfinite(t0) and math.isfinite(t1) and t1 > t0):
        raise ParameterError(f"The end time must be finite and greater than the start time {t0:g} s; got {t1!r}")
    if not (math.isfinite(sample_rate) and sample_rate > 0):
        raise ParameterError(f"The option 'sample_rate' must be a positive number; got {sample_rate!r}")
    n_out = int(math.floor((t1 - t0) * sample_rate + 1e-9)) + 1
    if n_out > 50_000_000:
        raise ParameterError(f"{n_out} output samples requested; lower sample_rate or t_end")
    if not (max_step > 0):
        raise ParameterError(f"The option 'max_step' must be positive; got {max_step!r}")
    if not (isinstance(estimate_samples, (int, np.integer)) and 64 <= estimate_samples <= 50_000_000):
        raise ParameterError(f"The option 'estimate_samples' must be an integer in [64, 5e7]; got {estimate_samples!r}")
    p = model.parameter_vector(params)
    try:
        y_s, l_s, vr0 = model.silent(params)
    except SilentMotionError as exc:
        raise SilentMotionError(f"cannot simulate: {exc}") from None
    try:
        modes: LinearModes | None = model.linear_modes(params)
    except (BrakesquealError, np.linalg.LinAlgError):
        modes = None
    y0, start = _initial_state(x0, perturbation, y_s, modes)
    atol_v = _check_tolerances(rtol, atol, math.sqrt(max(params.k_t, 1.0) / params.Theta))
    k = model.kernels
    l0 = l_s.copy()
    f0 = np.empty(4)
    k.rhs(y0, l0, p, f0)
    ev0 = np.empty(4)
    k.event_values(y0, l0, p, vr0, ev0)
    if not np.all(np.isfinite(f0)) or not np.all(np.isfinite(ev0)):
        raise ParameterError(f"the equations cannot be evaluated at the initial state {y0.tolist()}")
    for i in range(2):
        if ev0[i] <= 0:
            raise ParameterError(
                f"pad {i + 1} is out of contact at the initial state (F_n{i + 1} = {ev0[i]:.6g} N <= 0); "
                "use a smaller initial perturbation"
            )
        if ev0[i + 2] <= 0 and events != "off":
            raise ParameterError(f"pad {i + 1} does not slide forward at the initial state; use a smaller perturbation")
    t_out = t0 + np.arange(n_out) / sample_rate
    est = _EstimationGrid(t0, 1.0 / estimation_rate(modes, t1 - t0), int(estimate_samples))
    wall = time.perf_counter()
    if method == "DOP853-jit":
        res = _run_jit(k, y0, l0, f0, p, vr0, t0, t1, rtol, atol_v, max_step, t_out, est, events, max_steps,
                       progress)  # fmt: skip
    else:
        res = _run_scipy(model, params, k, y0, l0, p, vr0, t0, t1, method, rtol, atol_v, max_step, t_out, est,
                         events, progress)  # fmt: skip
    wall = time.perf_counter() - wall
    n = res["n"]
    Y = res["Y"][:n]
    L, C, E = k.post_process(Y, l_s, p) if n else (np.empty((0, 2)), np.empty((0, 12)), np.empty((0, 3)))
    return Trajectory(
        status=res["status"], message=res["message"], t=t_out[:n], y=Y, l=L, contact=C, kinetic=E,
        params=params, q_m0=y_s[:2].copy(), method=method, rtol=rtol, atol=atol_v, t_span=(t0, t1),
        t_event=res.get("t_event"), y_event=res.get("y_event"), event_times=res.get("event_times", {}),
        stats={"nfev": res["nfev"], "wall_s": wall, **res.get("stats", {})}, model=model.name,
        record=est.record(), modes=modes, sample_rate=float(sample_rate), y_start=y0.copy(), start=start,
    )  # fmt: skip


class _EstimationGrid:
    """The estimation record being filled: times ``t0 + i dt`` in a ring buffer of ``size`` rows."""

    def __init__(self, t0: float, dt: float, size: int) -> None:
        self.t0, self.dt = float(t0), float(dt)
        self.buf = np.full((size, 4), np.nan)
        self.count = 0  # samples written so far (index of the next one)

    def put(self, Y: np.ndarray) -> None:
        """Append samples (rows of ``Y``, at the next grid times)."""
        size, k = self.buf.shape[0], Y.shape[0]
        idx = (self.count + np.arange(k)) % size
        if k > size:
            idx, Y = idx[-size:], Y[-size:]
        self.buf[idx] = Y
        self.count += k

    def times(self, a: float, b: float) -> tuple[int, np.ndarray]:
        """Index of the first grid time ``>= a`` and the grid times in ``[a, b]``."""
        i0 = max(int(math.ceil((a - self.t0) / self.dt)) - 1, 0)
        while self.t0 + i0 * self.dt < a:
            i0 += 1
        i1 = int(math.floor((b - self.t0) / self.dt)) + 1
        while self.t0 + i1 * self.dt > b:
            i1 -= 1
        i = np.arange(i0, i1 + 1)
        return i0, self.t0 + i * self.dt

    def record(self) -> EstimationRecord:
        """The last ``min(count, size)`` samples in time order."""
        size = self.buf.shape[0]
        m = min(self.count, size)
        i = np.arange(self.count - m, self.count)
        return EstimationRecord(t=self.t0 + i * self.dt, y=self.buf[i % size].copy(), rate=1.0 / self.dt,
                                complete=self.count <= size)  # fmt: skip


def _dop853_tables() -> tuple[np.ndarray, ...]:
    from scipy.integrate._ivp import dop853_coefficients as c

    A = np.ascontiguousarray(c.A, dtype=float)
    return A, np.asarray(c.B, float), np.asarray(c.C, float), np.asarray(c.E3, float), np.asarray(c.E5, float), \
        np.ascontiguousarray(c.D, dtype=float)  # fmt: skip


def _run_jit(k, y0, l0, f0, p, vr0, t0, t1, rtol, atol, max_step, t_out, est, events, max_steps, progress):  # type: ignore[no-untyped-def]
    tables = _dop853_tables()
    i_est = 0
    Y = np.full((t_out.size, 4), np.nan)
    mode = {"off": 0, "stop": 1, "continue": 2}[events]
    ev_t = np.zeros(10000)
    ev_k = np.zeros(10000, dtype=np.int64)
    n_ev = 0
    y, l, f = y0.copy(), l0.copy(), f0.copy()
    h = min(1e-7, (t1 - t0) / 10)
    i_out = 0
    nfev = nstep = nrej = 0
    chunks = 50 if progress is not None else 1
    edges = np.linspace(t0, t1, chunks + 1)
    status, t_event, y_event, k_event = 0, None, None, -1
    t = t0
    for c in range(chunks):
        out = k.dop853(y, l, f, p, vr0, t, float(edges[c + 1]), h, rtol, atol, max_step, t_out, i_out, Y,
                       est.t0, est.dt, i_est, est.buf, mode, ev_t, ev_k, n_ev, max_steps - nstep,
                       *tables)  # fmt: skip
        status, t, y, l, f, h, i_out, n_ev, fe, ns, nr, k_event, te, ye, i_est = out
        est.count = int(i_est)
        nfev, nstep, nrej = nfev + fe, nstep + ns, nrej + nr
        if progress is not None:
            progress((t - t0) / (t1 - t0))
        if status != 0:
            if status == 1:
                t_event, y_event = float(te), np.asarray(ye).copy()
            break
    recorded: dict[str, list[float]] = {}
    for i in range(min(n_ev, ev_t.size)):
        recorded.setdefault(_EVENT_NAMES[int(ev_k[i])], []).append(float(ev_t[i]))
    st, msg = _status(status, t, k_event, t_event)
    return {"status": st, "message": msg, "Y": Y, "n": i_out, "nfev": int(nfev), "t_event": t_event,
            "y_event": y_event, "event_times": recorded, "stats": {"steps": int(nstep), "rejected": int(nrej)}}  # fmt: skip


def _status(code: int, t: float, k_event: int, t_event: float | None) -> tuple[str, str]:
    if code == 0:
        return "finished", "reached the end time"
    if code == 1:
        pad = k_event % 2 + 1
        if k_event < 2:
            return "contact-loss", f"pad {pad} lost contact (F_n{pad} <= 0) at t = {t_event:.6g} s"
        return "sliding-reversal", f"sliding at pad {pad} reversed (v_r{pad} . v_r0 <= 0) at t = {t_event:.6g} s"
    reason = {
        -1: "step size became too small",
        -2: "the state became non-finite or the pad equations g = 0 could not be solved",
        -3: "the step budget max_steps was exhausted",
    }.get(code, f"integrator error {code}")
    return "failed", f"integration failed at t = {t:.6g} s: {reason}"


def _run_scipy(model, params, k, y0, l0, p, vr0, t0, t1, method, rtol, atol, max_step, t_out, est, events, progress):  # type: ignore[no-untyped-def]
    """``solve_ivp`` in chunks no longer than the estimation ring buffer (bounded memory)."""
    from scipy.integrate import solve_ivp

    lbuf = l0.copy()
    calls = [0]

    def fun(t: float, y: np.ndarray) -> np.ndarray:
        out = np.empty(4)
        k.rhs(np.ascontiguousarray(y, dtype=float), lbuf, p, out)
        calls[0] += 1
        if progress is not None and calls[0] % 2000 == 0:
            progress((t - t0) / (t1 - t0))
        return out

    evfuns = []
    if events != "off":
        lev = l0.copy()
        vals = np.empty(4)

        def make(i: int) -> Callable[[float, np.ndarray], float]:
            def ev(t: float, y: np.ndarray) -> float:
                yy = np.ascontiguousarray(y, dtype=float)
                k.solve_l(yy, lev, p)
                k.event_values(yy, lev, p, vr0, vals)
                return float(vals[i])

            ev.terminal = events == "stop"  # type: ignore[attr-defined]
            ev.direction = -1  # type: ignore[attr-defined]
            return ev

        evfuns = [make(i) for i in range(4)]
    Y = np.full((t_out.size, 4), np.nan)
    n = 0
    nfev = 0
    t_event, y_event, k_event = None, None, -1
    recorded: dict[str, list[float]] = {}
    chunk = est.buf.shape[0] * est.dt
    a, y = t0, np.asarray(y0, dtype=float)
    code, t_end, sol_msg = 0, t0, ""
    first = True
    while True:
        b = min(a + chunk, t1)
        if t1 - b < 1e-9 * chunk:
            b = t1
        lo = "left" if first else "right"
        i0, i1 = np.searchsorted(t_out, a, side=lo), np.searchsorted(t_out, b, side="right")
        _, te = est.times(a, b)
        if not first:
            te = te[te > a]
        ts, inv = np.unique(np.concatenate([t_out[i0:i1], te, [b]]), return_inverse=True)
        sol = solve_ivp(fun, (a, b), y, method=method, t_eval=ts, rtol=rtol, atol=atol, max_step=max_step,
                        events=evfuns or None)  # fmt: skip
        nfev += int(sol.nfev)
        got = sol.t.size
        Yc = np.ascontiguousarray(sol.y.T)
        io, ie = inv[: i1 - i0], inv[i1 - i0 : i1 - i0 + te.size]
        ok_o, ok_e = io < got, ie < got
        Y[i0 : i0 + int(ok_o.sum())] = Yc[io[ok_o]]
        n = i0 + int(ok_o.sum())
        est.put(Yc[ie[ok_e]])
        if evfuns:
            for i, tev in enumerate(sol.t_events):
                if tev.size:
                    recorded.setdefault(_EVENT_NAMES[i], []).extend(float(v) for v in tev)
                    if sol.status == 1 and (t_event is None or tev[0] < t_event):
                        t_event, y_event, k_event = float(tev[0]), np.asarray(sol.y_events[i][0]), i
        code = {0: 0, 1: 1, -1: -2}[sol.status]
        t_end = float(sol.t[-1]) if got else a
        sol_msg = sol.message
        if code != 0 or b >= t1:
            break
        a, y, first = b, Yc[inv[-1]].copy(), False  # ts ends at b: the state to continue from
    if progress is not None:
        progress(1.0)
    st, msg = _status(code, t_end, k_event, t_event)
    if code == -2:
        msg = f"solve_ivp ({method}) failed: {sol_msg}"
    return {"status": st, "message": msg, "Y": Y, "n": n, "nfev": nfev, "t_event": t_event,
            "y_event": y_event, "event_times": recorded if events == "continue" else {}}  # fmt: skip
