r"""The simulation entry point :func:`simulate`: integrate any model's nonlinear equations (eq. 44 generalized)."""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Callable, Literal, Sequence

import numpy as np

from ..errors import ParameterError, SilentMotionError
from ..status import RunStatus
from ._model import SilentState, SimulationModel, _scales, _value, simulation_model
from ._run import EstimationGrid, Run, engagement_at
from ._stiffness import check_stiffness
from .estimate import LinearModes
from .trajectory import Trajectory

if TYPE_CHECKING:
    from ..codegen.engine import Engine
    from ..model.parameters import Parameters

__all__ = ["METHODS", "POINTS_PER_PERIOD", "START_AMPLITUDE", "simulate", "estimation_rate"]

#: Integration methods: the compiled DOP853 (default) and SciPy's ``solve_ivp`` methods.
METHODS: tuple[str, ...] = ("DOP853-jit", "DOP853", "RK45", "RK23", "Radau", "BDF", "LSODA")
#: Samples per period of the highest linear frequency in the estimation record (summary numbers).
POINTS_PER_PERIOD = 20
#: Largest number of output samples of one run (``sample_rate`` x duration).
MAX_OUTPUT_SAMPLES = 50_000_000
#: Largest deviation of the default start along the leading mode: tilt [rad] (a non-tilting disk: coordinate [m]).
START_AMPLITUDE = 1e-5
#: Output samples post-processed per compiled call (about 0.1 s).
_POST_BLOCK = 65536
EventMode = Literal["stop", "continue", "off"]
ContactLaw = Literal["bilateral", "unilateral"]
_Vector = Sequence[float] | np.ndarray


def _default_atol(model: SimulationModel, params: Parameters, rtol: float, modes: LinearModes | None) -> np.ndarray:
    """``1e-6 rtol`` times the scale of every component (:func:`_scales`), the rates' scale times
    ``w = sqrt(k_t/Theta)`` (a non-tilting disk: the largest ``|lambda|``)."""
    spec = model.spec
    if model.tilting:
        w = math.sqrt(max(_value(params, spec.disk.k_t), 1.0) / _value(params, spec.disk.Theta))
    else:
        w = float(np.abs(modes.eigenvalues).max()) if modes is not None else 1.0
        w = w if math.isfinite(w) and w > 0 else 1.0
    s = _scales(model, params)
    n = model.n
    return rtol * 1e-6 * np.concatenate([s[:n], s[:n] * w, s[n:]])


def _check_tolerances(rtol: float, atol: float | Sequence[float] | None, default: np.ndarray) -> np.ndarray:
    if not (isinstance(rtol, (int, float)) and math.isfinite(rtol) and 1e-13 <= rtol <= 1e-2):
        raise ParameterError(f"The option 'rtol' must be in [1e-13, 1e-2]; got {rtol!r}", parameter="rtol")
    if atol is None:
        return default
    try:
        a = np.broadcast_to(np.asarray(atol, dtype=float), default.shape).copy()
    except (ValueError, TypeError):
        raise ParameterError(f"The option 'atol' must be one value or {default.size}; got {atol!r}",
                             parameter="atol") from None
    if not np.all(np.isfinite(a)) or np.any(a <= 0) or np.any(a > 1.0):
        raise ParameterError(f"The option 'atol' must be in (0, 1] (one value or {default.size}); got {atol!r}",
                             parameter="atol")
    return a


def _start_vector(model: SimulationModel, modes: LinearModes, scales: np.ndarray) -> np.ndarray:
    """``Re(v_0)`` scaled so that its largest coordinate or pad state relative to its scale is ``START_AMPLITUDE``."""
    v = np.real(modes.right[:, 0])
    n = model.n
    ref = np.concatenate([v[:n], v[2 * n:]]) / scales
    s = float(np.abs(ref).max())
    return START_AMPLITUDE * v / (s if s > 0 else 1.0)


def _pads_at_rest(model: SimulationModel, params: Parameters, p: np.ndarray, y0: np.ndarray, st: SilentState) -> str:
    """Start every damped pad (a :attr:`~SimulationModel.dynamic` pad with ``d_ip > 0``) at rest on its support.

    When the initial state leaves the pad states out, the damped pads' deformations ``l`` are set (in ``y0``,
    in place) to the root of their balance with ``ldot = 0``: the spring carries the friction at the initial
    tilt.  Kept at the silent motion's value instead, a tilted start would put the whole change of the friction
    force on the damper (``ldot ~ dF / d_ip``, often faster than the sliding speed: a spurious reversal).
    Returns a note for the trajectory's ``start`` ("" when no pad is changed).
    """
    undamped = set(model.undamped(params))
    dyn = [j for j, k in enumerate(model.pad_kinds) if k == "dynamic"]
    damped = [(i, j) for i, j in enumerate(dyn) if model.pad_unknowns[j] not in undamped]
    if not damped:
        return ""
    n, m = model.n, len(model.pad_kinds)
    l, dl, g = st.l.copy(), np.zeros(m), np.empty(2 * m + 1)
    for i, j in damped:
        l[j] = y0[2 * n + i]
    for _ in range(60):  # G is l + O(c_ip) in l (eqs. 33-34): a secant-free fixed point converges at once
        model.kernels.pad_balance(y0, l, dl, p, g)
        step = max(abs(float(g[j])) for _i, j in damped)
        for i, j in damped:
            l[j] -= g[j]
        if not step > 1e-15 * (1.0 + max(abs(float(l[j])) for _i, j in damped)):
            break
    if not all(math.isfinite(float(l[j])) for _i, j in damped):
        return ""
    for i, j in damped:
        y0[2 * n + i] = l[j]
    return "; damped pads at rest on their supports (ldot = 0)"


def _initial_state(model: SimulationModel, x0: _Vector | None, perturbation: _Vector | None, y_s: np.ndarray,
                   modes: LinearModes | None, scales: np.ndarray) -> tuple[np.ndarray, str]:
    """Initial state and a description of it (``start`` of the trajectory)."""
    n, N = model.n, y_s.size
    names = model.state_names
    if x0 is not None and perturbation is not None:
        raise ParameterError("give either x0 (absolute initial state) or perturbation, not both")
    if x0 is not None:
        v = np.asarray(x0, dtype=float).ravel()
        if v.size not in (2 * n, N):
            sizes = f"{2 * n}" + (f" or {N}" if N > 2 * n else "")
            raise ParameterError(f"The initial state x0 must have {sizes} values ({', '.join(names[:2 * n])}"
                                 f"{', ' + ', '.join(names[2 * n:]) if N > 2 * n else ''}); got {v.size}")
        y0, start = np.concatenate([v, y_s[v.size:]]), "x0 (absolute state)"
    elif perturbation is None and modes is not None:
        y0 = y_s + _start_vector(model, modes, scales)
        start = "leading mode, real part of its eigenvector, "
        if model.tilting and model.n == 2 and not model.dynamic:
            start += f"max tilt deviation {START_AMPLITUDE:g} rad"
        else:
            length = float(max(v for v, c in zip(scales, (*model.coords, *model.dynamic))
                               if c not in ("q1", "q2") or not model.tilting))
            start += (f"max deviation {START_AMPLITUDE:g} of a coordinate or pad state relative to its scale "
                      f"(tilts 1 rad, lengths {length:g} m)")
    else:
        if perturbation is None:
            d = np.zeros(n)
            d[0] = START_AMPLITUDE * scales[0]
        else:
            d = np.asarray(perturbation, dtype=float).ravel()
        if d.size not in (n, 2 * n, N):
            raise ParameterError(
                f"The perturbation must have {n} ({', '.join(names[:n])}) or {2 * n} values (with the rates "
                f"{', '.join(names[n:2 * n])}){f' or {N} (with the pad states)' if N > 2 * n else ''}; got {d.size}")
        y0 = y_s + np.concatenate([d, np.zeros(N - d.size)])
        start = "perturbation of the silent motion"
    if not np.all(np.isfinite(y0)):
        raise ParameterError(f"The initial state must be finite; got {y0.tolist()}")
    if model.tilting and np.any(np.abs(y0[:2]) >= 0.5 * math.pi):
        raise ParameterError(f"The initial tilt angles must be in (-pi/2, pi/2); got {y0[:2].tolist()}")
    return y0, start


def estimation_rate(modes: LinearModes | None, duration: float) -> float:
    """Sampling rate [Hz] of the estimation record: ``POINTS_PER_PERIOD`` per period of the fastest mode.

    The "frequency" of a mode is ``|lambda| / 2 pi`` (so that a real, fast
    eigenvalue is resolved too); at least 64 samples cover ``duration``.

    Parameters
    ----------
    modes : LinearModes or None
        Linear modes of the silent motion; without them the rate is 64
        samples over the run.
    duration : float
        Duration of the run [s].

    Returns
    -------
    float
        The rate [Hz].
    """
    fmax = float(np.abs(modes.eigenvalues).max()) / (2 * math.pi) if modes is not None else 0.0
    return max(POINTS_PER_PERIOD * fmax, 64.0 / duration)


def simulate(
    model: SimulationModel | Engine,
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
    contact: ContactLaw = "bilateral",
) -> Trajectory:
    r"""Integrate the nonlinear equations of any model (eq. 44 generalized) from a perturbed silent motion.

    Parameters
    ----------
    model : SimulationModel or Engine
        The model (:func:`~._model.simulation_model`), or its engine (:func:`brakesqueal.engine`; the
        public :func:`brakesqueal.simulate` builds it from ``params``).
    params : Parameters
        Parameter values (of the model; the paper's 17-parameter sets are accepted for the paper's model).
    t_span : float or (float, float)
        End time ``t_end`` [s] (start 0) or ``(t0, t_end)``; ``t_end > t0``.
    x0 : array_like, shape (2n,) or (2n + k,), optional
        Absolute initial state ``(Q, Qdot[, L_dynamic])`` (the paper's model:
        ``(q1, q2, dq1, dq2)`` [rad, rad/s]).
    perturbation : array_like, shape (n,), (2n,) or (2n + k,), optional
        Initial deviation from the silent motion (rates zero if ``n`` values).
        Default when neither is given: along the leading mode of the
        linearization, ``x(0) = Re(v_0)`` with ``v_0`` its right eigenvector
        scaled so that its largest coordinate or pad state, in units of 1 rad
        for a tilt and of the largest pad radius for a length, is
        ``START_AMPLITUDE = 1e-5`` (the paper's model: the largest tilt
        deviation is 1e-5 rad).
    method : str
        ``"DOP853-jit"`` (compiled Dormand–Prince 8(5,3), default) or one of
        SciPy's ``solve_ivp`` methods ``"DOP853", "RK45", "RK23", "Radau",
        "BDF", "LSODA"`` (the same compiled right-hand side, called from Python; slower).
    rtol : float
        Relative tolerance, in ``[1e-13, 1e-2]``.
    atol : float or array_like (2n + k,), optional
        Absolute tolerance(s) in ``(0, 1]``; default ``1e-6 rtol`` times 1 for
        tilts [rad], the largest pad radius for lengths [m], and those times
        ``w = sqrt(k_t/Theta)`` for the rates (a non-tilting disk: the
        largest ``|lambda|``).
    sample_rate : float
        Output samples per second [Hz] (uniform grid, dense output) of
        :attr:`Trajectory.t` / :attr:`Trajectory.y` (NetCDF, WAV, plot).  The
        summary numbers do not use this grid but the estimation record
        (``estimate_samples``).
    events : {"stop", "continue", "off"}
        ``"stop"`` ends the run at the first contact loss (``F_n <= 0``) or
        sliding reversal (``v_r . v_r0 <= 0``, ``v_r0`` the silent-motion
        sliding velocity of that pad) of any pad; ``"continue"`` records the
        event times (``contact-loss-pad-<name>``, ``sliding-reversal-pad-<name>``)
        and integrates on with the same equations (bilateral contact, friction
        direction ``v_r/|v_r|``); ``"off"`` ignores them.  When every pad has
        regularised stick-slip (law ``stick``,
        :func:`~brakesqueal.model.options.regularised_pads` with ``stick_speed``)
        a sliding reversal is ordinary motion: ``"stop"`` stops at a contact
        loss only and records the reversals in :attr:`Trajectory.event_times`.
    max_step : float
        Largest step [s].
    max_steps : int
        Step budget (compiled method); exceeding it ends the run with status ``"failed"``.
    progress : callable, optional
        Called with the fraction done (0..1) while integrating (about every 0.1 s of wall time).
    estimate_samples : int
        Length of the estimation record (default 65536): the integrator's
        dense output at ``POINTS_PER_PERIOD = 20`` samples per period of the
        fastest linear mode (:func:`estimation_rate`), of which the last
        ``estimate_samples`` are kept (a ring buffer).  :attr:`Trajectory.summary`
        is computed from it.
    contact : {"bilateral", "unilateral"}
        ``"bilateral"`` (default): the equations hold with any sign of ``F_n``
        (``events`` decides what happens at a contact loss).
        ``"unilateral"``: the normal force of every pad is ``max(0, F_n)``
        (``docs/simulation.md``, unilateral contact): at ``F_n = 0`` the pad
        lifts off (its contact force and friction vanish, the run goes on), and it
        comes back when its ``F_n`` (the force the support would exert at
        the disk's surface) turns positive again; lift-offs and re-contacts
        are recorded in :attr:`Trajectory.event_times`
        (``contact-loss-pad-<name>``, ``re-contact-pad-<name>``) and the
        contact state per sample in :attr:`Trajectory.engaged`.  Needs
        ``method="DOP853-jit"`` and events ``"stop"`` (the run stops at a
        sliding reversal, where Coulomb friction would stick) or
        ``"continue"`` (sliding reversals recorded, the friction direction
        follows ``v_r/|v_r|``).  Not available for pads with rate-dependent
        friction (their tangential deformation is a state): ``ldot`` enters
        the pad's balance ``G(Q, Qdot, l, ldot) = 0`` through the friction
        force and ``F_n``, so ``dG/dldot`` shrinks with ``F_n`` (at ``F_n = 0``
        only the support damper's share is left) and can change sign while
        the pad is still pressed: the pad mode ``-G_l / G_ldot`` diverges
        before lift-off (``docs/simulation.md``, unilateral contact).

    Returns
    -------
    Trajectory
        Status, message, samples and summary numbers; the partial trajectory
        is kept when the run stops early.

    Raises
    ------
    ParameterError
        Bad options or initial state (non-finite, ``t_end <= t0``, tolerances
        out of range, a pad out of contact at the initial state); or, before
        anything is integrated, a span that the model's stiffness makes
        infeasible for an explicit method: more than ``max(1e8, max_steps)``
        steps by the lower bound ``(t_end - t0) max|lambda| / 6.8`` (``lambda``
        the eigenvalues of the linearization at the silent motion; the message
        gives the estimate, the time it would take and the parameters the
        fastest time scale depends on; implicit methods are not limited).
    SilentMotionError
        If the silent motion does not exist (needed for the reference state).
    KeyboardInterrupt
        On Ctrl-C: the compiled integrator runs in calls of about 0.1 s, and
        the interrupt takes effect between them (nothing is returned).

    Notes
    -----
    Massless pads with coulomb friction are quasi-static (``ldot := 0``,
    ``l`` from ``G(Q, Qdot, l, 0) = 0``); with rate-dependent friction their
    deformation is a state and ``ldot`` solves ``G(Q, Qdot, l, ldot) = 0``
    (``docs/simulation.md``).
    """
    if method not in METHODS:
        raise ParameterError(f"The option 'method' must be one of {', '.join(METHODS)}; got {method!r}",
                             parameter="method")
    if events not in ("stop", "continue", "off"):
        raise ParameterError(f"The option 'events' must be one of stop, continue, off; got {events!r}",
                             parameter="events")
    if contact not in ("bilateral", "unilateral"):
        raise ParameterError(f"The option 'contact' must be bilateral or unilateral; got {contact!r}",
                             parameter="contact")
    if contact == "unilateral" and (method != "DOP853-jit" or events == "off"):
        raise ParameterError("contact='unilateral' needs method='DOP853-jit' and events 'stop' or 'continue'; got "
                             f"method={method!r}, events={events!r}")
    if np.ndim(t_span) == 0:
        t0, t1 = 0.0, float(t_span)  # type: ignore[arg-type]
    else:
        t0, t1 = (float(v) for v in t_span)  # type: ignore[union-attr]
    if not (math.isfinite(t0) and math.isfinite(t1) and t1 > t0):
        raise ParameterError(f"The end time must be finite and greater than the start time {t0:g} s; got {t1!r}",
                             parameter="t_end")
    if not (math.isfinite(sample_rate) and sample_rate > 0):
        raise ParameterError(f"The option 'sample_rate' must be a positive number; got {sample_rate!r}",
                             parameter="sample_rate")
    samples = (t1 - t0) * sample_rate  # a float: no overflow converting an enormous count to int
    if not samples < MAX_OUTPUT_SAMPLES:
        raise ParameterError(f"The options 'sample_rate' and 't_end' ask for {samples:.3g} output samples "
                             f"(sample_rate x duration); at most {MAX_OUTPUT_SAMPLES:.0e} are allowed: lower "
                             "'sample_rate' or 't_end'", parameter="sample_rate", names=("t_end",))
    n_out = int(math.floor(samples + 1e-9)) + 1
    if not (max_step > 0):
        raise ParameterError(f"The option 'max_step' must be positive; got {max_step!r}")
    if not (isinstance(estimate_samples, (int, np.integer)) and 64 <= estimate_samples <= 50_000_000):
        raise ParameterError(f"The option 'estimate_samples' must be an integer in [64, 5e7]; got {estimate_samples!r}")
    from ..analysis.equilibrium import as_parameters
    from ._interrupt import interrupt_guard

    with interrupt_guard():
        return _simulate(model, as_parameters(params), t0, t1, x0, perturbation, method, rtol, atol, sample_rate,
                         events, max_step, max_steps, progress, estimate_samples, n_out, contact)


def _simulate(model: SimulationModel | Engine, params: Parameters, t0: float, t1: float, x0: _Vector | None,
              perturbation: _Vector | None,
              method: str, rtol: float, atol: float | Sequence[float] | None, sample_rate: float, events: str,
              max_step: float, max_steps: int, progress: Callable[[float], None] | None, estimate_samples: int,
              n_out: int, contact: str = "bilateral") -> Trajectory:
    from ._interrupt import check_interrupt

    if not isinstance(model, SimulationModel):
        from ..codegen.engine import Engine

        if not isinstance(model, Engine):
            raise ParameterError(f"The argument 'model' must be a SimulationModel or an Engine (brakesqueal.simulate"
                                 f"(params, ...) builds it from the parameters); got {type(model).__name__}",
                                 parameter="model")
        model = simulation_model(model)
    check_interrupt()
    params = model.parameters(params)
    p = model.parameter_vector(params)
    unilateral = contact == "unilateral"
    if unilateral and (undamped := model.undamped(params)):
        raise ParameterError(f"contact='unilateral' needs a tangential damper d_ip > 0 on every pad whose rate is a "
                             f"state ({', '.join(undamped)}, rate-dependent friction): without one its rate ldot "
                             "solves the friction balance G(Q, Qdot, l, ldot) = 0, whose slope dG/dldot shrinks "
                             "with F_n and can change sign before F_n = 0, so the pad mode diverges before the "
                             "pad lifts off (docs/simulation.md, unilateral contact); give the pads a d_ip, use "
                             "coulomb friction or contact='bilateral'")
    try:
        st = model.silent(params)
    except SilentMotionError as exc:
        raise type(exc)(f"cannot simulate: {exc}") from None
    modes = model.linear_modes(params)
    check_interrupt()
    y0, start = _initial_state(model, x0, perturbation, st.y, modes, _scales(model, params))
    given = np.asarray(x0 if x0 is not None else perturbation if perturbation is not None else [], dtype=float)
    if (x0 is not None or perturbation is not None) and given.size < y0.size:
        start += _pads_at_rest(model, params, p, y0, st)
    atol_v = _check_tolerances(rtol, atol, _default_atol(model, params, rtol, modes))
    k = model.kernels
    npad = len(model.pads)
    l0, dl0 = st.l.copy(), st.dl.copy()
    f0 = np.empty(y0.size)
    g, mw = np.empty(2 * l0.size + 1), np.empty(model.n * model.n + model.n)
    k.rhs(y0, l0, dl0, p, st.ztol, g, mw, f0)
    ev0 = np.empty(2 * npad)
    k.event_values(y0, l0, dl0, p, st.vr0, np.empty(7 * npad), ev0)
    if not np.all(np.isfinite(f0)) or not np.all(np.isfinite(ev0)):
        raise ParameterError(f"the equations cannot be evaluated at the initial state {y0.tolist()}")
    # a span the model's stiffness makes infeasible for an explicit method is refused before the run
    check_stiffness(model, params, t0, t1, method, max_steps, modes,
                    lambda: k.rhs(y0, l0.copy(), dl0.copy(), p, st.ztol, g, mw, np.empty(y0.size)))
    eng0 = (ev0[:npad] > 0).astype(np.int64) if unilateral else np.ones(npad, dtype=np.int64)
    for j, pad in enumerate(model.pads):
        if ev0[j] <= 0 and not unilateral:
            raise ParameterError(f"pad '{pad}' is out of contact at the initial state (F_n = {ev0[j]:.6g} N <= 0); "
                                 "use a smaller initial perturbation")
        if ev0[npad + j] <= 0 and events != "off" and eng0[j]:
            raise ParameterError(f"pad '{pad}' does not slide forward at the initial state; use a smaller "
                                 "perturbation")
    t_out = t0 + np.arange(n_out) / sample_rate
    est = EstimationGrid(t0, 1.0 / estimation_rate(modes, t1 - t0), int(estimate_samples), y0.size)
    if unilateral and not eng0.all():
        D0 = np.empty(npad * model.n + 1)
        k.rhs_u(y0, l0, dl0, p, st.ztol, g, mw, eng0, D0, f0)
        k.event_values_u(y0, l0, dl0, p, st.vr0, np.empty(7 * npad), eng0, ev0)
    run = Run(model, p, st, y0, l0, dl0, f0, ev0, t0, t1, rtol, atol_v, max_step, t_out, est, events, progress,
               eng0 if unilateral else None)
    wall = time.perf_counter()
    res = run.jit(max_steps) if method == "DOP853-jit" else run.scipy(method)
    wall = time.perf_counter() - wall
    check_interrupt()
    n = res["n"]
    Y = res["Y"][:n]
    m = st.l.size
    L, dL = np.full((n, m), np.nan), np.full((n, m), np.nan)
    C, E = np.full((n, 7 * npad), np.nan), np.full((n, 5), np.nan)
    lw, dlw = st.l.copy(), st.dl.copy()  # warm starts carried from block to block
    engaged = None
    if unilateral:
        engaged = engagement_at(t_out[:n], eng0.astype(bool), res.get("switch_times", [[] for _ in range(npad)]))
    ENG = (np.ones((n, npad), dtype=np.int64) if engaged is None else engaged.astype(np.int64))
    for a in range(0, n, _POST_BLOCK):  # blocks of bounded wall time: Ctrl-C acts between them
        b = min(a + _POST_BLOCK, n)
        k.post_process(Y[a:b], b - a, lw, dlw, p, st.ztol, ENG[a:b], L[a:b], dL[a:b], C[a:b], E[a:b])
        check_interrupt()
    if engaged is not None:
        C[:, 0::7] = np.where(engaged, C[:, 0::7], 0.0)  # the acting normal force max(0, F_n)
    message = res["message"]
    if res["status"] == RunStatus.FAILED and model.dynamic and n:
        Fn = C[:, 0::7]
        last = np.flatnonzero(np.all(np.isfinite(Fn), axis=1))
        if last.size and (ref := float(np.max(np.abs(Fn[0])))) > 0 and float(Fn[last[-1]].min()) < 0.2 * ref:
            message += (f"; a pad's normal force had fallen to {float(Fn[last[-1]].min()):.4g} N (from "
                        f"{ref:.4g} N): a pad with rate-dependent friction cannot reach contact loss when its rate "
                        "balance degenerates first (docs/simulation.md, unilateral contact)")
    return Trajectory(
        status=res["status"], message=message, t=t_out[:n], y=Y, l=L, contact=C.reshape(n, npad, 7),
        energy_terms=E, params=params, q0=np.asarray(st.silent.q0, dtype=float).copy(), method=method, rtol=rtol,
        atol=atol_v, t_span=(t0, t1), t_event=res.get("t_event"), y_event=res.get("y_event"),
        event_times=res.get("event_times", {}), stats={"nfev": res["nfev"], "wall_s": wall, **res.get("stats", {})},
        model=model.name, record=est.record(), modes=modes, sample_rate=float(sample_rate), y_start=y0.copy(),
        start=start, coords=model.coords, pads=model.pads, pad_unknowns=model.pad_unknowns, dynamic=model.dynamic,
        tilting=model.tilting, y_silent=st.y.copy(), l_rates=dL, event_pad=res.get("event_pad"),
        contact_law=contact, engaged=engaged, t_final=float(res["t_final"]),
    )  # fmt: skip


