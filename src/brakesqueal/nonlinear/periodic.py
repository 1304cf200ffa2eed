r"""Periodic orbits by (multiple) shooting, Floquet multipliers and stability.

Unknowns: the states ``X_0 ... X_{m-1}`` at the starts of ``m`` equal time
segments and the period ``T``.  Equations (``phi`` is the flow, see
:mod:`.flow`):

.. math::

   \varphi(X_i, T/m; p) - X_{i+1 \bmod m} = 0,\qquad
   \langle f(X^{ref}_0, p),\, X_0 - X^{ref}_0\rangle = 0 \quad\text{(Poincaré phase condition)}.

Newton's method uses the segment monodromy matrices ``M_i`` (variational
equations, or finite differences, as the flow says) and the columns
``f(phi_i) / m`` for ``T``.  The monodromy matrix of the orbit is
``M = M_{m-1} ... M_0``; since ``M f(X_0) = f(X_0)``, its eigenvalues are 1
and those of the reduced matrix ``V^T M V`` (``V``: orthonormal basis of
``f(X_0)^perp``), which are the non-trivial Floquet multipliers (conjugate
pairs stay together).  The orbit is stable when all of them lie strictly
inside the unit circle.  The distance of the eigenvalue of ``M`` nearest to 1
from 1 is reported as a check (``trivial_multiplier_error``) and bounds the
verdict (``verdict``: ``"undecided"`` where a non-trivial multiplier lies within
``multiplier_accuracy`` of the unit circle; :mod:`.floquet`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import BrakesquealError, ParameterError
from .floquet import multiplier_accuracy, stability_verdict
from .flow import Event, FlowError, FlowResult, ScipyFlow
from .hopf import CycleGuess
from .system import PiecewiseSystem, SmoothSystem

__all__ = ["PeriodicOrbit", "find_periodic_orbit", "floquet_multipliers", "ShootingError"]


class ShootingError(BrakesquealError):
    """Newton's method for a periodic orbit did not converge."""


@dataclass(frozen=True)
class PeriodicOrbit:
    """A periodic orbit with its Floquet multipliers.

    Attributes
    ----------
    x : ndarray, shape (m, n)
        States at the starts of the ``m`` shooting segments (``x[0]`` fixes the phase).
    period : float
        Period ``T`` [s].
    p : float
        Parameter value.
    multipliers : ndarray, shape (n,), complex
        All eigenvalues of the monodromy matrix, sorted by decreasing modulus.
    floquet : ndarray, shape (n - 1,), complex
        Non-trivial multipliers (eigenvalues of the reduced monodromy), sorted
        by decreasing modulus.
    monodromy : ndarray, shape (n, n)
        Monodromy matrix ``M`` at ``x[0]``.
    stable : bool
        All non-trivial multipliers strictly inside the unit circle.
    n_unstable : int
        Number of non-trivial multipliers outside the unit circle.
    trivial_multiplier_error : float
        ``min |mu - 1|`` over the eigenvalues of ``M`` (should be ~ the integration tolerance).
    residual : float
        Scaled max-norm of the shooting residual at the returned point.
    iterations : int
        Newton iterations.
    monodromy_method : str
        ``"variational"`` or ``"finite-difference"``.
    t : ndarray, shape (N,)
        Uniform sample times over one period.
    samples : ndarray, shape (N, n)
        States at ``t``.
    amplitude : ndarray, shape (n,)
        First-harmonic amplitude of each coordinate (``2 |X_1| / N`` of the DFT).
    mean : ndarray, shape (n,)
        Mean over one period.
    x_max, x_min : ndarray, shape (n,)
        Extremes over the samples.
    events : tuple of Event
        Switching events over one period (piecewise systems).
    sample_modes : ndarray of int
        Mode of each sample (empty for smooth systems).
    state_names : tuple of str
        Coordinate names.
    parameter_name : str
        Parameter name.
    multiplier_accuracy : float
        How far from the unit circle a non-trivial multiplier must lie for its side to count
        (:func:`~.floquet.multiplier_accuracy`: from ``trivial_multiplier_error`` and the integration tolerance).
    verdict : str
        ``"stable"``, ``"unstable"`` or ``"undecided"`` (:func:`~.floquet.stability_verdict`): ``stable`` and
        ``n_unstable`` count the multipliers' computed side of the unit circle, the verdict only a side farther
        than ``multiplier_accuracy``.
    multiplier_change : float
        For a close call (the largest non-trivial ``|mu|`` within :data:`CLOSE_CALL` times the accuracy of 1):
        how much it changes when the monodromy is integrated again at a 100 times smaller tolerance; it widens
        ``multiplier_accuracy`` to at least twice that.  ``nan`` where not checked.
    """

    x: np.ndarray
    period: float
    p: float
    multipliers: np.ndarray
    floquet: np.ndarray
    monodromy: np.ndarray = field(repr=False)
    stable: bool = False
    n_unstable: int = 0
    trivial_multiplier_error: float = float("nan")
    residual: float = float("nan")
    iterations: int = 0
    monodromy_method: str = "variational"
    t: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)
    samples: np.ndarray = field(default_factory=lambda: np.empty((0, 0)), repr=False)
    amplitude: np.ndarray = field(default_factory=lambda: np.empty(0))
    mean: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)
    x_max: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)
    x_min: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)
    events: tuple[Event, ...] = ()
    sample_modes: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=int), repr=False)
    state_names: tuple[str, ...] = ()
    parameter_name: str = "p"
    multiplier_accuracy: float = float("nan")
    verdict: str = "undecided"
    multiplier_change: float = float("nan")

    @property
    def omega(self) -> float:
        """Angular frequency ``2 pi / T`` [rad/s]."""
        return 2 * math.pi / self.period

    @property
    def frequency(self) -> float:
        """Frequency ``1 / T`` [Hz]."""
        return 1.0 / self.period

    def as_dict(self) -> dict[str, Any]:
        """A JSON-friendly summary.

        Returns
        -------
        dict
            Period, frequency, amplitudes, multipliers (``[re, im]`` pairs), stability.
        """
        return {
            "parameter": self.parameter_name,
            "p": self.p,
            "period": self.period,
            "frequency_hz": self.frequency,
            "amplitude": dict(zip(self.state_names, map(float, self.amplitude))),
            "floquet": [[float(m.real), float(m.imag)] for m in self.floquet],
            "stable": self.stable,
            "trivial_multiplier_error": self.trivial_multiplier_error,
            "multiplier_accuracy": self.multiplier_accuracy,
            "verdict": self.verdict,
            "multiplier_change": self.multiplier_change,
            "monodromy_method": self.monodromy_method,
            "events": [e.name for e in self.events],
        }


def floquet_multipliers(M: np.ndarray, f0: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Eigenvalues of the monodromy matrix and the non-trivial multipliers.

    Parameters
    ----------
    M : ndarray, shape (n, n)
        Monodromy matrix at a point ``x0`` of the orbit.
    f0 : ndarray, shape (n,)
        Vector field at ``x0`` (``M f0 = f0``).

    Returns
    -------
    all : ndarray, shape (n,)
        Eigenvalues of ``M``, sorted by decreasing modulus.
    nontrivial : ndarray, shape (n - 1,)
        Eigenvalues of ``V^T M V`` with ``V`` an orthonormal basis of
        ``f0^perp``, sorted by decreasing modulus.
    trivial_error : float
        ``min |mu - 1|`` over ``all``.
    """
    M = np.asarray(M, dtype=float)
    n = M.shape[0]
    lam = np.linalg.eigvals(M)
    lam = lam[np.argsort(-np.abs(lam), kind="stable")]
    nf = float(np.linalg.norm(f0))
    if nf == 0 or not math.isfinite(nf):
        raise ShootingError("the vector field vanishes on the orbit (an equilibrium, not a cycle)")
    Q, _ = np.linalg.qr(np.column_stack([f0 / nf, np.eye(n)]))
    V = Q[:, 1:n]
    red = np.linalg.eigvals(V.T @ M @ V) if n > 1 else np.empty(0, complex)
    red = red[np.argsort(-np.abs(red), kind="stable")]
    return lam.astype(complex), red.astype(complex), float(np.min(np.abs(lam - 1.0)))


# ------------------------------------------------------------- shooting core
@dataclass
class _Eval:
    R: np.ndarray  # (m n,) residual
    JX: np.ndarray  # (m n, m n)
    JT: np.ndarray  # (m n,)
    Jp: np.ndarray | None  # (m n,)
    flows: list[FlowResult]


def _evaluate(flow: Any, X: np.ndarray, T: float, p: float, scale: np.ndarray, n_samples: int = 0) -> _Eval:
    """Residual and Jacobian blocks of the multiple-shooting equations."""
    m, n = X.shape
    R = np.empty(m * n)
    JX = np.zeros((m * n, m * n))
    JT = np.empty(m * n)
    Jp = np.empty(m * n)
    have_p = True
    flows = []
    ns = -(-n_samples // m) if n_samples else 0
    for i in range(m):
        fr = flow(X[i], T / m, p, sensitivities=True, n_samples=ns, scale=scale)
        flows.append(fr)
        j = (i + 1) % m
        sl = slice(i * n, (i + 1) * n)
        R[sl] = fr.x - X[j]
        JX[sl, i * n:(i + 1) * n] += fr.monodromy
        JX[sl, j * n:(j + 1) * n] -= np.eye(n)
        JT[sl] = fr.f_end / m
        if fr.dp is None:
            have_p = False
        else:
            Jp[sl] = fr.dp
    return _Eval(R, JX, JT, Jp if have_p else None, flows)


def _system_of(flow: Any) -> Any:
    return getattr(flow, "system")


def _vector_field(system: Any, x: np.ndarray, p: float) -> np.ndarray:
    pw = system.as_piecewise()
    return pw.modes[int(pw.mode_of(x, p))].rhs(x, p)


def _sampled(flow: Any, X: np.ndarray, T: float, p: float, scale: np.ndarray, n_samples: int,
             flows: list[FlowResult] | None = None) -> dict[str, Any]:  # fmt: skip
    """Samples over one period (one plain flow per segment), amplitudes, extremes and events.

    With ``n_samples = 0`` the given ``flows`` only provide the events and the sample fields are empty.
    """
    m, n = X.shape
    t_list: list[np.ndarray] = []
    s_list: list[np.ndarray] = []
    md_list: list[int] = []
    events: list[Event] = []
    ns = -(-n_samples // m) if n_samples else 0
    for i in range(m):
        fr = flow(X[i], T / m, p, sensitivities=False, n_samples=ns, scale=scale) if ns else flows[i]  # type: ignore[index]
        if ns:
            assert fr.t_samples is not None and fr.x_samples is not None  # asked for: n_samples > 0
            t_list.append(i * T / m + fr.t_samples)
            s_list.append(fr.x_samples)
            md_list.extend(fr.modes)
        events.extend(Event(t=e.t + i * T / m, name=e.name, source=e.source, target=e.target,
                            transversality=e.transversality, x=e.x) for e in fr.events)  # fmt: skip
    if s_list:
        S = np.vstack(s_list)
        out = {"t": np.concatenate(t_list), "samples": S,
               "amplitude": 2 * np.abs(np.fft.rfft(S, axis=0)[1]) / S.shape[0],
               "mean": S.mean(axis=0), "x_max": S.max(axis=0), "x_min": S.min(axis=0)}  # fmt: skip
    else:
        nan = np.full(n, np.nan)
        out = {"t": np.empty(0), "samples": np.empty((0, n)), "amplitude": nan, "mean": nan, "x_max": nan, "x_min": nan}
    out["events"] = tuple(events)
    out["sample_modes"] = np.asarray(md_list, dtype=int)
    return out


def _orbit_from(flow: Any, X: np.ndarray, T: float, p: float, ev: _Eval, scale: np.ndarray, iterations: int,
                residual: float, n_samples: int) -> PeriodicOrbit:  # fmt: skip
    """The orbit record: multipliers from ``ev``, samples from one plain flow per segment."""
    system = _system_of(flow)
    n = X.shape[1]
    M = np.eye(n)
    for fr in ev.flows:
        assert fr.monodromy is not None  # the Newton flows carry sensitivities
        M = fr.monodromy @ M
    f0 = _vector_field(system, X[0], p)
    lam, red, terr = floquet_multipliers(M, f0)
    n_unst = int(np.count_nonzero(np.abs(red) > 1.0))
    method = ev.flows[0].monodromy_method
    accuracy = multiplier_accuracy(terr, getattr(flow, "rtol", None), method=method, segments=X.shape[0])
    verdict = stability_verdict(red, accuracy)
    change = math.nan
    if verdict != "undecided" and red.size and abs(float(np.max(np.abs(red))) - 1.0) < CLOSE_CALL * accuracy:
        # a close call: the monodromy again at a 100 times smaller tolerance; the change bounds the error too
        change = _tolerance_change(flow, X, T, p, red, f0, scale)
        if math.isfinite(change):
            accuracy = max(accuracy, 2.0 * change)
            verdict = stability_verdict(red, accuracy)
    return PeriodicOrbit(
        x=X.copy(), period=float(T), p=float(p), multipliers=lam, floquet=red, monodromy=M,
        stable=bool(n_unst == 0), n_unstable=n_unst, trivial_multiplier_error=terr, residual=float(residual),
        iterations=iterations, monodromy_method=method,
        state_names=tuple(system.state_names), parameter_name=system.parameter_name,
        multiplier_accuracy=accuracy, verdict=verdict, multiplier_change=change,
        **_sampled(flow, X, T, p, scale, n_samples, ev.flows),
    )  # fmt: skip


#: A decided verdict whose largest non-trivial ``|mu|`` lies within this many times the accuracy bound of 1 is
#: checked by a second monodromy at a 100 times smaller integration tolerance (:attr:`PeriodicOrbit.multiplier_change`).
CLOSE_CALL: float = 1e4


def _tolerance_change(flow: Any, X: np.ndarray, T: float, p: float, red: np.ndarray, f0: np.ndarray,
                      scale: np.ndarray) -> float:
    """Change of the largest non-trivial ``|mu|`` when the monodromy is integrated at ``rtol / 100`` (at least
    ``1e-13``); ``nan`` for a flow without a dataclass ``rtol`` or already at the floor, or if the flow fails."""
    import dataclasses

    rt = getattr(flow, "rtol", None)
    if not dataclasses.is_dataclass(flow) or isinstance(flow, type) or not isinstance(rt, (int, float)):
        return math.nan
    tight = max(float(rt) / 100.0, 1e-13)
    if tight >= float(rt):
        return math.nan
    try:
        fine: Any = dataclasses.replace(flow, rtol=tight)
        m, n = X.shape
        M = np.eye(n)
        for i in range(m):
            fr = fine(X[i], T / m, p, sensitivities=True, scale=scale)
            M = fr.monodromy @ M
        _, red2, _ = floquet_multipliers(M, f0)
    except (FlowError, ParameterError, ShootingError):
        return math.nan
    return float(abs(np.max(np.abs(red)) - np.max(np.abs(red2))))


def _resampled(flow: Any, orbit: PeriodicOrbit, scale: np.ndarray, n_samples: int) -> PeriodicOrbit:
    """``orbit`` with its samples (re)computed."""
    from dataclasses import replace

    return replace(orbit, **_sampled(flow, orbit.x, orbit.period, orbit.p, scale, n_samples))


def _guard_clearance(system: Any, x: np.ndarray, p: float, scale: np.ndarray) -> float:
    """Scaled distance ``min |h| / |grad h * scale|`` of ``x`` from every guard (``inf`` without guards)."""
    pw = system.as_piecewise()
    out = math.inf
    for trs in pw.transitions:
        for tr in trs:
            g = tr.grad(x, p) * scale
            ng = float(np.linalg.norm(g))
            if ng > 0:
                out = min(out, abs(float(tr.guard(x, p))) / ng)
    return out


def _best_phase(system: Any, samples: np.ndarray, p: float, scale: np.ndarray) -> int:
    """Index of the sample farthest from every guard."""
    return int(np.argmax([_guard_clearance(system, x, p, scale) for x in samples]))


def _return_time(flow: Any, system: Any, x0: np.ndarray, T: float, p: float) -> float:
    """First return time to the section ``<f(x0), x - x0> = 0`` (crossed upwards) within ``2 T``, else ``T``."""
    f0 = _vector_field(system, x0, p)
    fr = flow(x0, 2 * T, p, sensitivities=False, n_samples=800)
    sv = (fr.x_samples - x0) @ f0
    k = np.flatnonzero((sv[1:-1] < 0) & (sv[2:] >= 0))
    if k.size == 0:
        return T
    i = int(k[0]) + 1
    t = fr.t_samples
    return float(t[i] + (t[i + 1] - t[i]) * (-sv[i]) / (sv[i + 1] - sv[i]))


def _minimal_period_factor(flow: Any, x0: np.ndarray, T: float, p: float, scale: np.ndarray, tol: float) -> int:
    """The largest ``k <= 8`` with ``phi(x0, T / k) = x0`` (an orbit traversed ``k`` times), else 1."""
    fr = flow(x0, T, p, sensitivities=False, n_samples=840, scale=scale)  # 840 = lcm(1..8)
    S = fr.x_samples
    for k in range(8, 1, -1):
        if np.all(np.max(np.abs(S[840 // k :: 840 // k] - x0) / scale, axis=1) < 1e-6):
            return k
    return 1


def _scale_from(X: np.ndarray, samples: np.ndarray | None) -> np.ndarray:
    """Per-coordinate scale: half the range over the orbit, floored at 1e-4 of the largest (tolerances)."""
    data = samples if samples is not None and samples.size else X
    half = 0.5 * (data.max(axis=0) - data.min(axis=0))
    top = float(np.max(half)) if half.size else 0.0
    if top == 0.0:
        top = max(float(np.max(np.abs(X))), 1.0)
    return np.maximum(half, 1e-4 * top)


def _make_flow(system: Any, flow: Any) -> Any:
    if flow is not None:
        return flow
    if not isinstance(system, (SmoothSystem, PiecewiseSystem)):
        raise ParameterError(f"'system' must be a SmoothSystem or PiecewiseSystem; got {type(system).__name__}")
    default = getattr(system, "default_flow", None)  # e.g. a brake model's compiled flow (compiled.model_flow)
    if callable(default):
        return default()
    return ScipyFlow(system)


def find_periodic_orbit(system: SmoothSystem | PiecewiseSystem, guess: CycleGuess | Any, *, period: float | None = None,
                        p: float | None = None, n_segments: int | None = None, flow: Any = None, tol: float = 1e-10,
                        max_iter: int = 40, n_samples: int = 64, settle: float = 0.0) -> PeriodicOrbit:  # fmt: skip
    r"""A periodic orbit at fixed ``p`` by (multiple) shooting with a Poincaré phase condition.

    Parameters
    ----------
    system : SmoothSystem or PiecewiseSystem
        The system (ignored when ``flow`` is given: the flow's system is used).
    guess : CycleGuess or array_like
        A :class:`~.hopf.CycleGuess` (e.g. ``HopfResult.cycle_guess(p)``), or
        initial state(s) of shape ``(n,)`` or ``(m, n)``.
    period : float, optional
        Period guess [s] (required unless ``guess`` is a CycleGuess).
    p : float, optional
        Parameter (required unless ``guess`` is a CycleGuess).
    n_segments : int, optional
        Number of shooting segments ``m``; states for the extra segments are
        generated by integrating the guess (default: ``len(guess.x)``, i.e.
        single shooting for a one-point guess).
    flow : Flow, optional
        Integrator with sensitivities (default :class:`~.flow.ScipyFlow`).
    tol : float
        Newton tolerance on the scaled update (state over its amplitude, ``T``
        relative), default ``1e-10``.  Newton also stops when the scaled residual is within ten times the
        flow's ``rtol`` and the update has stopped shrinking: the integration's own error then bounds what
        further iterations could achieve (the orbit's ``residual`` reports it).
    max_iter : int
        Maximum Newton iterations.
    n_samples : int
        Uniform samples over one period for amplitudes and extremes (>= 8).
    settle : float
        Integrate the guess forward over ``settle`` periods before shooting
        (helps from a poor guess of a stable orbit; default 0).

    Returns
    -------
    PeriodicOrbit
        The orbit, its multipliers and stability.  If the converged period is
        a multiple ``k T'`` of a shorter period (the orbit closes after
        ``T / k``, ``k <= 8``), the orbit with the minimal period is returned.

    Raises
    ------
    ShootingError
        Newton's method did not converge (or converged to an equilibrium).
    ParameterError
        Bad guess, period or options.
    """
    flow = _make_flow(system, flow)
    system = _system_of(flow)
    if isinstance(guess, CycleGuess):
        X = np.array(guess.x, dtype=float, ndmin=2)
        T = float(guess.period if period is None else period)
        pv = float(guess.p if p is None else p)
    else:
        X = np.array(guess, dtype=float, ndmin=2)
        if period is None or p is None:
            raise ParameterError("find_periodic_orbit: give 'period' and 'p' with an array guess")
        T, pv = float(period), float(p)
    n = system.n
    if X.shape[1] != n or not np.all(np.isfinite(X)):
        raise ParameterError(f"The guess must have shape (n,) or (m, n) with n = {n} finite values; got {X.shape}")
    if not (math.isfinite(T) and T > 0):
        raise ParameterError(f"The period guess must be positive and finite; got {T!r}")
    if not (isinstance(n_samples, (int, np.integer)) and n_samples >= 8):
        raise ParameterError(f"The option 'n_samples' must be an integer >= 8; got {n_samples!r}")
    if not (0 < tol < 1e-2):
        raise ParameterError(f"The option 'tol' must be in (0, 1e-2); got {tol!r}")
    if not (isinstance(settle, (int, float)) and math.isfinite(settle) and settle >= 0):
        raise ParameterError(f"The option 'settle' must be a number >= 0 of periods; got {settle!r}")
    if settle > 0:
        X = flow(X[0], settle * T, pv, sensitivities=False).x[None, :]
        T = _return_time(flow, system, X[0], T, pv)
    if n_segments is not None and n_segments != X.shape[0]:
        if not (isinstance(n_segments, (int, np.integer)) and n_segments >= 1):
            raise ParameterError(f"The option 'n_segments' must be a positive integer; got {n_segments!r}")
        fr = flow(X[0], T, pv, sensitivities=False, n_samples=n_segments)
        X = fr.x_samples.copy()
    m = X.shape[0]
    pre = flow(X[0], T, pv, sensitivities=False, n_samples=n_samples)
    scale = _scale_from(X, pre.x_samples)
    if m == 1 and _guard_clearance(system, X[0], pv, scale) < 1e-3:
        # a phase point on a switching surface makes the monodromy ill-defined: start elsewhere on the guess
        X = pre.x_samples[_best_phase(system, pre.x_samples, pv, scale)][None, :].copy()
    xref = X[0].copy()
    fref = _vector_field(system, xref, pv)
    fnorm = float(np.linalg.norm(fref / scale))
    if fnorm == 0:
        raise ParameterError("the guess is an equilibrium (f = 0): give a point on the cycle")
    phase_row = (fref / scale) / fnorm  # in scaled variables
    sv = np.concatenate([np.tile(scale, m), [T]])
    noise = 10 * float(getattr(flow, "rtol", 0.0))  # scaled residual the flow's own error can leave
    it = 0
    last = np.inf
    ev = None
    for it in range(1, max_iter + 1):
        try:
            ev = _evaluate(flow, X, T, pv, scale)
        except FlowError as exc:
            raise ShootingError(f"shooting failed at iteration {it}: {exc}") from None
        N = m * n
        Jm = np.zeros((N + 1, N + 1))
        Jm[:N, :N] = ev.JX * sv[None, :N]
        Jm[:N, N] = ev.JT * T
        Jm[N, :n] = phase_row
        rhs = np.concatenate([ev.R / np.tile(scale, m), [float(phase_row @ ((X[0] - xref) / scale))]])
        Jm[:N, :] /= np.tile(scale, m)[:, None]
        try:
            d = -np.linalg.solve(Jm, rhs)
        except np.linalg.LinAlgError:
            raise ShootingError("singular shooting Jacobian (the orbit is not isolated at fixed p)") from None
        step = float(np.max(np.abs(d)))
        res = float(np.max(np.abs(rhs)))
        # converged: the update is below tol, or the residual sits at the integration's noise floor and
        # Newton no longer shrinks the update (an ill-conditioned Jacobian times that noise; seen with a
        # piecewise flow through contact loss: residual 1e-12, condition 2e6, updates stuck near 5e-7)
        if step < tol or (res <= noise and it >= 3 and step >= 0.5 * last):
            k = _minimal_period_factor(flow, X[0], T, pv, scale, tol)
            if k > 1:
                return find_periodic_orbit(system, X[0], period=T / k, p=pv, n_segments=m, flow=flow, tol=tol,
                                           max_iter=max_iter, n_samples=n_samples)  # fmt: skip
            return _orbit_from(flow, X, T, pv, ev, scale, it, res, n_samples)
        # trust region: at most one amplitude scale in the states and 20 % in the period per step
        lam = min(1.0, 1.0 / step, 0.2 / max(abs(d[N]), 1e-300))
        X = X + lam * (d[:N] * sv[:N]).reshape(m, n)
        T = T * (1 + lam * d[N])
        last = step
    raise ShootingError(f"shooting did not converge in {max_iter} iterations (last scaled step {last:.3g}) "
                        f"at {system.parameter_name} = {pv:.12g}")  # fmt: skip
