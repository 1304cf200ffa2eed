r"""The result of :func:`~brakesqueal.simulation.simulate`: samples, summary numbers, plot, export, audio."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np

from .estimate import LinearModes, ModeEstimate, dominant_mode, modal_projection

if TYPE_CHECKING:
    from ..model.parameters import Parameters

__all__ = ["EstimationRecord", "Trajectory", "Summary", "envelope", "fit_growth_frequency", "integration_error_bound",
           "summarize"]


def envelope(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Hilbert envelope and unwrapped phase of the columns of ``x`` (shape ``(n, k)``).

    The envelope is ``sqrt(sum_k |analytic(x_k)|^2)`` (a whirl of constant
    radius has a constant envelope); the phase is that of the column with the
    larger RMS value.  Each column's mean is removed before the Hilbert
    transform (:func:`scipy.signal.hilbert`).

    Parameters
    ----------
    x : ndarray, shape (n,) or (n, k)
        Uniformly sampled signals, one per column (e.g. the tilt deviations
        ``q_m - q_m0`` [rad]); a 1-D array is one signal.

    Returns
    -------
    envelope : ndarray, shape (n,)
        Combined envelope, in the unit of ``x``.
    phase : ndarray, shape (n,)
        Unwrapped phase of the analytic signal of the dominant column [rad].
    """
    from scipy.signal import hilbert

    x = np.atleast_2d(np.asarray(x, dtype=float).T).T
    z = hilbert(x - x.mean(axis=0), axis=0)
    env = np.sqrt(np.sum(np.abs(z) ** 2, axis=1))
    j = int(np.argmax(np.sqrt(np.mean(x**2, axis=0))))
    return env, np.unwrap(np.angle(z[:, j]))


def _zero_crossing_frequency(t: np.ndarray, x: np.ndarray) -> float:
    """Mean frequency [Hz] from linearly interpolated upward zero crossings (NaN if fewer than 3).

    ``x`` must oscillate about zero (a deviation from the silent motion); no mean
    is removed, because the mean of a growing oscillation is not its centre.
    """
    i = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    if i.size < 3:
        return math.nan
    tz = t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])
    return float((i.size - 1) / (tz[-1] - tz[0]))


def fit_growth_frequency(t: np.ndarray, x: np.ndarray, trim: float = 0.1) -> tuple[float, float]:
    """Least-squares growth rate [1/s] of ``log(envelope)`` and the dominant frequency [Hz].

    ``trim`` of the record is dropped at each end (Hilbert edge effects).  The
    frequency comes from interpolated zero crossings of the column with the
    larger RMS value over the same window (unbiased for growing or decaying
    sinusoids, unlike the slope of the Hilbert phase); the Hilbert phase is the
    fallback when there are fewer than three crossings.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Uniform sample times [s].
    x : ndarray, shape (n,) or (n, k)
        Deviations from the silent motion (oscillating about zero), one signal
        per column; see :func:`envelope`.
    trim : float, optional
        Fraction of the record dropped at each end (default 0.1, i.e. the
        central 80 % is fitted).

    Returns
    -------
    growth : float
        Exponential growth rate of the envelope [1/s] (negative: decaying).
    frequency : float
        Dominant frequency [Hz].  Both are NaN when fewer than four samples
        with a positive envelope remain in the window.
    """
    env, phase = envelope(x)
    n = t.size
    a, b = int(trim * n), max(int((1 - trim) * n), int(trim * n) + 2)
    tt = t[a:b]
    ok = env[a:b] > 0
    if tt.size < 4 or ok.sum() < 4:
        return math.nan, math.nan
    growth = float(np.polyfit(tt[ok], np.log(env[a:b][ok]), 1)[0])
    cols = np.atleast_2d(np.asarray(x, dtype=float).T).T
    j = int(np.argmax(np.sqrt(np.mean(cols**2, axis=0))))
    freq = _zero_crossing_frequency(tt, cols[a:b, j])
    if not math.isfinite(freq):
        freq = abs(float(np.polyfit(tt, phase[a:b], 1)[0] / (2 * math.pi)))
    return growth, freq


def _clean(v: Any) -> Any:
    """JSON-ready value: non-finite floats become ``None``, tuples lists, dicts and lists recursively."""
    if isinstance(v, float) and not math.isfinite(v):
        return None
    if isinstance(v, (tuple, list)):
        return [_clean(u) for u in v]
    if isinstance(v, dict):
        return {k: _clean(u) for k, u in v.items()}
    return v


@dataclass(frozen=True)
class Summary:
    """Summary numbers of a trajectory (see :func:`summarize` and ``docs/simulation.md``).

    Attributes
    ----------
    status : str
        ``"finished"``, ``"contact-loss"``, ``"sliding-reversal"`` or ``"failed"``.
    frequency_hz : float
        Frequency of the leading mode [Hz], ``Im lambda / 2 pi`` estimated
        from the motion (``estimator``).
    growth_rate : float
        Growth rate of the leading mode [1/s], ``Re lambda`` estimated from
        the motion (negative: decaying).
    amplitude_final : float
        ``max |q - q0|`` (Euclidean norm of the coordinates' deviation) over
        the last two periods of the estimation record.
    limit_cycle_amplitude : float or None
        Mean envelope over the last quarter of the estimation record when the
        growth has stopped there (|local rate| x quarter length < 0.02) after
        the amplitude grew by more than a factor 1.5 from the start; else
        ``None``.
    growth_rate_stderr, frequency_stderr : float
        Uncertainties of ``growth_rate`` [1/s] and ``frequency_hz`` [Hz]: the
        root sum of squares of the terms in ``uncertainty_terms``.
    estimator : str
        ``"modal-projection"`` (onto the leading mode of the linearization),
        ``"matrix-pencil"`` (no linear model: the dominant mode) or
        ``"none"``.
    estimate_window : (float, float)
        First and last time [s] of the samples the estimate used.
    estimate_rate_hz : float
        Their sampling rate [Hz] (the integrator's dense output, 20 samples
        per period of the fastest linear mode; not the output ``sample_rate``).
    linear_growth_rate, linear_frequency_hz : float or None
        ``Re lambda`` [1/s] and ``Im lambda / 2 pi`` [Hz] of the leading
        eigenvalue of the linearization; the estimate agrees with them while
        the motion is small (linear).
    uncertainty_terms : dict
        ``fit_growth`` [1/s] and ``fit_frequency`` [Hz]: the fit's own
        uncertainty (:class:`~brakesqueal.simulation.estimate.ModeEstimate`);
        ``integration`` [1/s]: a bound on the integrator's error of growth
        rate and angular frequency (per-step relative tolerance of the
        leading modal coordinate, or of the deviation without a linear model,
        times accepted steps per second; divided by 2 pi for the frequency;
        :func:`integration_error_bound`).
    regime : str
        ``"linear"`` when growth rate and frequency agree with the linear
        eigenvalue within 3 uncertainties, ``"nonlinear"`` when not (an
        amplitude-dependent growth rate or frequency: the numbers are averages
        over the window), ``"unknown"`` without a linear model or estimate.
    cross_check : dict or None
        The matrix-pencil estimate of the same mode (keys ``estimator``,
        ``growth_rate``, ``growth_rate_stderr``, ``frequency_hz``,
        ``frequency_stderr``, ``window``), an estimate independent of the
        linear model, over the last (at most 512 decimated) samples; a warning
        is added when it disagrees with the projection over that window by
        more than 5 combined fit uncertainties.
    warnings : tuple of str
        Conditions that make a number doubtful (aliased output samples,
        a leading mode that does not dominate, disagreeing estimators, ...).
    estimate_status : str
        ``"ok"``; ``"too-few-samples"`` (fewer than :data:`MIN_ESTIMATE_SAMPLES`) or
        ``"window-shorter-than-a-period"`` (the estimation window is shorter than one period of the
        leading mode, linear or estimated): then growth rate, frequency and their uncertainties are not
        estimated (NaN; ``None`` in :meth:`to_dict`) and a warning says why.
    """

    status: str
    frequency_hz: float
    growth_rate: float
    amplitude_final: float
    limit_cycle_amplitude: float | None
    growth_rate_stderr: float = math.nan
    frequency_stderr: float = math.nan
    estimator: str = "none"
    estimate_window: tuple[float, float] = (math.nan, math.nan)
    estimate_rate_hz: float = math.nan
    linear_growth_rate: float | None = None
    linear_frequency_hz: float | None = None
    uncertainty_terms: dict[str, float] | None = None
    regime: str = "unknown"
    cross_check: dict[str, Any] | None = None
    warnings: tuple[str, ...] = ()
    estimate_status: str = "ok"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (non-finite numbers become ``None``; tuples become lists)."""
        return {k: _clean(v) for k, v in self.__dict__.items()}


@dataclass(frozen=True, eq=False)
class EstimationRecord:
    """Uniform dense-output samples of the state kept for the summary numbers.

    Attributes
    ----------
    t : ndarray, shape (N,)
        Times [s], uniform.
    y : ndarray, shape (N, 2n)
        States ``(q, dq)`` (absolute, not deviations).
    rate : float
        Sampling rate [Hz].
    complete : bool
        ``True`` when the record covers the whole run; ``False`` when it is
        the last ``N`` samples of a longer run (ring buffer).
    """

    t: np.ndarray
    y: np.ndarray
    rate: float
    complete: bool


#: RHS evaluations per accepted step of SciPy's explicit methods (implicit ones: counted as 1, conservative).
_STAGES = {"DOP853": 12, "RK45": 6, "RK23": 3}


def integration_error_bound(
    x: np.ndarray, y: np.ndarray, rtol: float, atol: np.ndarray | float, steps: float, duration: float,
    mode: np.ndarray | None = None,
) -> float:
    """Bound on an adaptive integrator's error of a growth rate and an angular frequency [1/s].

    Every accepted step keeps its local error estimate below
    ``s_j = rtol |y_j| + atol_j`` per component.  Relative to the deviation
    ``x`` that is ``tau = max_j s_j / RMS(x_j)`` (with ``max |y_j|``); with
    the left eigenvector ``w`` of the estimated mode (``mode``), the relative
    error of its modal coordinate ``z = w^H x`` instead,
    ``tau = sum_j |w_j| s_j / RMS(|z|)`` (components that hardly move, such as
    a caliper's tangential coordinate in a mode of the disk, then do not
    dominate).  Errors in amplitude and phase of a (nearly) neutral
    oscillation add up from step to step, so growth rate and angular
    frequency can be off by at most about ``tau`` times the accepted steps
    per second.  DOP853's error estimate is that of a lower-order
    combination, so the true error is usually much smaller (measured at
    paper-fig2, ``rtol = 1e-9``: under 1 % of this bound).

    Parameters
    ----------
    x : ndarray, shape (N, m)
        State deviations over the estimation window.
    y : ndarray, shape (N, m)
        Absolute states (what the tolerance refers to).
    rtol : float
        Relative tolerance.
    atol : float or ndarray, shape (m,)
        Absolute tolerance(s).
    steps : float
        Accepted steps over the run.
    duration : float
        Duration of the run [s].
    mode : ndarray, shape (m,), optional
        Left eigenvector of the estimated mode (modal projection).

    Returns
    -------
    float
        The bound [1/s]; 0 when ``steps`` or ``duration`` is not positive or
        ``x`` is zero.
    """
    x = np.asarray(x, dtype=float)
    if not (steps > 0 and duration > 0) or x.size == 0:
        return 0.0
    ymax = np.nanmax(np.abs(np.asarray(y, dtype=float)), axis=0)
    rms = np.sqrt(np.nanmean(x**2, axis=0))
    at = np.broadcast_to(np.asarray(atol, dtype=float), rms.shape)
    if mode is not None:
        w = np.asarray(mode, dtype=complex)
        z = np.abs(np.where(np.isfinite(x), x, 0.0) @ np.conj(w))
        zr = math.sqrt(float(np.mean(z**2)))
        if zr > 0:
            return float(np.sum(np.abs(w) * (rtol * ymax + at))) / zr * steps / duration
    ok = rms > 0
    if not ok.any():
        return 0.0
    tau = float(np.max((rtol * ymax[ok] + at[ok]) / rms[ok]))
    return tau * steps / duration


def _agree(a: float, sa: float, b: float, sb: float, slack: float) -> bool:
    """Two estimates agree within 5 combined uncertainties plus ``slack``."""
    if not (math.isfinite(a) and math.isfinite(b)):
        return True
    tol = 5 * math.hypot(sa if math.isfinite(sa) else 0.0, sb if math.isfinite(sb) else 0.0) + slack
    return abs(a - b) <= tol


#: Fewest samples of the estimation record from which growth rate and frequency are estimated.
MIN_ESTIMATE_SAMPLES = 16


def _window_too_short(status: str, t: np.ndarray, x: np.ndarray, n: int, lin_g: float | None, lin_f: float | None,
                      f_lead: float) -> Summary:
    """The summary of a record shorter than one period of the leading mode: no growth rate or frequency."""
    amp = float(np.sqrt((x[:, :n] ** 2).sum(axis=1)).max())
    duration = float(t[-1] - t[0])
    if f_lead > 0:
        warn = (f"the estimation window ({duration:.3g} s) is shorter than one period of the leading mode "
                f"({1 / f_lead:.3g} s at {f_lead:.6g} Hz): growth rate and frequency cannot be estimated; simulate "
                "for longer")
    else:  # an estimated frequency of exactly 0 (e.g. a motion frozen by an enormous damping): no period at all
        warn = (f"the motion does not oscillate within the estimation window ({duration:.3g} s, estimated "
                "frequency 0 Hz): growth rate and frequency cannot be estimated; simulate for longer")
    return Summary(status, math.nan, math.nan, amp, None, estimate_window=(float(t[0]), float(t[-1])),
                   estimate_rate_hz=float((t.size - 1) / duration) if duration > 0 else math.nan,
                   linear_growth_rate=lin_g, linear_frequency_hz=lin_f, warnings=(warn,),
                   estimate_status="window-shorter-than-a-period")


def summarize(
    status: str,
    t: np.ndarray,
    x: np.ndarray,
    modes: LinearModes | None,
    *,
    output_rate: float | None = None,
    x_start: np.ndarray | None = None,
    integration_error: float = 0.0,
    cross_check: bool = True,
    coordinates: int | None = None,
) -> Summary:
    """Summary numbers from uniformly sampled state deviations (any number of coordinates).

    Parameters
    ----------
    status : str
        Status of the run (copied).
    t : ndarray, shape (N,)
        Uniform sample times [s] at a rate well above the frequencies of the
        motion (e.g. :class:`EstimationRecord`).
    x : ndarray, shape (N, 2n)
        State deviations from the equilibrium ``(q - q0, dq)``.
    modes : LinearModes or None
        Linear modes of the equilibrium (modal projection onto the leading
        one); ``None``: matrix pencil, dominant mode.
    output_rate : float, optional
        Sampling rate [Hz] of the user's output grid; a warning is added when
        it is below twice the leading frequency.
    x_start : ndarray, shape (2n,), optional
        Initial deviation, for the "grew from the start" test of the limit
        cycle (default: the envelope at 10 % of the record).
    integration_error : float, optional
        Bound on the integrator's error of growth rate and angular frequency
        [1/s] (default 0), added to the uncertainties.
    cross_check : bool, optional
        Also run the matrix pencil on the same samples (default ``True``).
    coordinates : int, optional
        Number of coordinates ``n`` among the state components (default half
        of them); a state ``(dq, dqdot, extra)`` with ``k`` more first-order
        components (pads kept as states) has ``2n + k`` columns.

    Returns
    -------
    Summary
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    n = coordinates if coordinates else (max(x.shape[1] // 2, 1) if x.ndim == 2 else 1)
    nan = math.nan
    warns: list[str] = []
    lin_g = lin_f = None
    if modes is not None:
        lin_g, lin_f = float(modes.leading.real), float(modes.leading.imag / (2 * math.pi))
    if t.size < MIN_ESTIMATE_SAMPLES:
        amp = nan if t.size == 0 else float(np.sqrt((x[:, :n] ** 2).sum(axis=1)).max())
        return Summary(status, nan, nan, amp, None, linear_growth_rate=lin_g, linear_frequency_hz=lin_f,
                       warnings=(f"only {t.size} samples (fewer than {MIN_ESTIMATE_SAMPLES}): growth rate and "
                                 "frequency cannot be estimated",), estimate_status="too-few-samples")  # fmt: skip
    duration = float(t[-1] - t[0])
    if lin_f is not None and lin_f > 0 and duration * lin_f < 1:
        return _window_too_short(status, t, x, n, lin_g, lin_f, lin_f)
    est: ModeEstimate = (modal_projection(t, x, modes, coordinates=n) if modes is not None
                         else dominant_mode(t, x, coordinates=n))
    if modes is None and math.isfinite(est.frequency_hz) and duration * abs(est.frequency_hz) < 1:
        return _window_too_short(status, t, x, n, lin_g, lin_f, abs(est.frequency_hz))
    warns.extend(est.warnings)
    ie = float(integration_error)
    terms = {"fit_growth": est.growth_rate_stderr, "fit_frequency": est.frequency_stderr, "integration": ie}
    g_err = math.hypot(est.growth_rate_stderr, ie)
    f_err = math.hypot(est.frequency_stderr, ie / (2 * math.pi))
    regime = "unknown"
    if modes is not None and math.isfinite(g_err) and math.isfinite(f_err):
        lin = (abs(est.growth_rate - modes.leading.real) <= 3 * g_err
               and abs(est.frequency_hz - modes.leading.imag / (2 * math.pi)) <= 3 * f_err)  # fmt: skip
        regime = "linear" if lin else "nonlinear"
    cc = None
    if cross_check and modes is not None and math.isfinite(est.growth_rate):
        try:
            pen = dominant_mode(t, x, reference=est.eigenvalue, max_samples=512, coordinates=n)
        except Exception as exc:  # noqa: BLE001 - a failed cross-check is reported, never fatal
            warns.append(f"matrix-pencil cross-check failed: {exc}")
        else:
            cc = {k: getattr(pen, k) for k in ("estimator", "growth_rate", "growth_rate_stderr", "frequency_hz",
                                                "frequency_stderr", "window")}  # fmt: skip
            # compare with the projection over the pencil's (shorter) window: the same samples, so only the
            # fits' own uncertainties count (the growth rate of a nonlinear motion varies between windows)
            inside = (t >= pen.window[0]) & (t <= pen.window[1])
            ref = modal_projection(t[inside], x[inside], modes, coordinates=n) if inside.sum() >= 16 else est
            scale = 1e-9 * abs(est.eigenvalue)
            if not (_agree(ref.growth_rate, ref.growth_rate_stderr, pen.growth_rate, pen.growth_rate_stderr, scale)
                    and _agree(ref.frequency_hz, ref.frequency_stderr, pen.frequency_hz, pen.frequency_stderr,
                               scale / (2 * math.pi))):  # fmt: skip
                warns.append(
                    f"the matrix-pencil cross-check over t = {pen.window[0]:.6g}..{pen.window[1]:.6g} s disagrees "
                    f"with the projection: growth {pen.growth_rate:.6g} vs {ref.growth_rate:.6g} 1/s, frequency "
                    f"{pen.frequency_hz:.8g} vs {ref.frequency_hz:.8g} Hz"
                )
    f_lead = max(abs(est.frequency_hz) if math.isfinite(est.frequency_hz) else 0.0, abs(lin_f or 0.0))
    if output_rate is not None and f_lead > 0 and output_rate < 2 * f_lead:
        warns.append(
            f"the output sample rate {output_rate:.6g} Hz is below twice the leading frequency "
            f"({f_lead:.6g} Hz): the output samples (NetCDF, WAV, plot) are aliased; "
            f"the summary uses the integrator's dense output at {1 / (t[1] - t[0]):.6g} Hz"
        )
    # amplitudes from the same record
    fs = 1.0 / float(t[1] - t[0])
    per = int(2 * fs / f_lead) if f_lead > 0 else t.size // 10
    per = max(min(per, t.size), 2)
    norm = np.sqrt((x[:, :n] ** 2).sum(axis=1))
    amp = float(norm[-per:].max())
    lc = None
    N = t.size
    env = envelope(x[:, :n])[0] if status == "finished" and N > 400 and np.all(np.isfinite(x[:, :n])) else None
    q, e = N // 4, N // 20
    if env is not None and env[-q - e : -e].min() > 0:
        seg_t, seg = t[-q - e : -e], env[-q - e : -e]
        local = float(np.polyfit(seg_t, np.log(seg), 1)[0])
        if x_start is not None and f_lead > 0:
            xs = np.asarray(x_start, dtype=float)
            a0 = math.sqrt(float((xs[:n] ** 2).sum()) + float((xs[n:2 * n] ** 2).sum()) / (2 * math.pi * f_lead) ** 2)
        else:
            a0 = float(env[N // 10])
        if abs(local) * (seg_t[-1] - seg_t[0]) < 0.02 and seg.mean() > 1.5 * a0:
            lc = float(seg.mean())
    return Summary(status, est.frequency_hz, est.growth_rate, amp, lc, g_err, f_err, est.estimator, est.window,
                   est.rate_hz, lin_g, lin_f, terms, regime, cc, tuple(warns))  # fmt: skip


@dataclass(frozen=True, eq=False)
class Trajectory:
    """A simulated motion of any model.

    Attributes
    ----------
    status, message : str
        How the run ended (a :class:`~brakesqueal.status.RunStatus`, which is a ``str``; see
        :class:`Summary`) and a one-line explanation.
    t : ndarray, shape (N,)
        Uniform output times [s].
    y : ndarray, shape (N, 2n + k)
        Integrator state ``(Q, Qdot, L_dynamic)``: coordinates (tilts [rad],
        displacements [m]), their rates, and the deformations of the pads with
        rate-dependent friction (``k`` of them; none for the paper's model,
        whose ``y`` is ``(q1, q2, dq1, dq2)``).
    l : ndarray, shape (N, m)
        Tangential deformations ``L`` of the massless pads [m] (quasi-static
        ones solved, dynamic ones from ``y``).
    contact : ndarray, shape (N, n_pads, 7)
        Per pad :data:`~brakesqueal.codegen.compiled.CONTACT_FIELDS`:
        ``F_n`` [N], ``v_r`` (3) [m/s], ``h`` [m], ``hdot`` [m/s], ``l`` [m].
    energy_terms : ndarray, shape (N, 5)
        ``T2, T1, T0, V_support, V_pads`` [J] (see :meth:`energy`).
    params : Parameters
    q0 : ndarray, shape (n,)
        Coordinates at the silent motion.
    method : str
    rtol : float
    atol : ndarray
    t_span : (float, float)
    t_event, y_event : float or None, ndarray or None
        Time and state of the terminal event, if the run stopped at one.
    event_times : dict
        Recorded event times by name (``events="continue"`` or unilateral
        contact): ``contact-loss-pad-<name>``, ``sliding-reversal-pad-<name>``,
        ``re-contact-pad-<name>``.
    stats : dict
        ``nfev``, ``wall_s`` and (compiled method) ``steps``, ``rejected``.
    contact_law : str
        ``"bilateral"`` or ``"unilateral"`` (:func:`~brakesqueal.simulation.simulate`'s ``contact``).
    engaged : ndarray of bool, shape (N, n_pads), or None
        Unilateral contact: whether each pad is pressed at each output sample.
    t_final : float
        Time [s] at which the integration ended (:attr:`t_end_reached`); NaN when not recorded.
    model : str
        The model's name.
    record : EstimationRecord or None
        Dense output at a rate set by the linear frequencies (the last part
        of a long run), from which :attr:`summary` is computed.
    modes : LinearModes or None
        Linear modes of the silent motion for the state ``y - y_silent``.
    sample_rate : float
        Rate of the output grid ``t`` [Hz].
    y_start : ndarray or None
        Initial state.
    start : str
        How the initial state was chosen.
    coords : tuple of str
        Names of the coordinates ``Q`` (``q1, q2, w1, u1, wc_caliper, ...``).
    pads : tuple of str
        Pad names (the ``pad`` dimension of the arrays).
    pad_unknowns : tuple of str
        Names of the columns of ``l`` (``l_<pad>``).
    dynamic : tuple of str
        Pad deformations that are states (the last ``k`` columns of ``y``).
    tilting : bool
        Whether the disk tilts (``q1, q2`` are the first two coordinates).
    y_silent : ndarray or None
        The silent motion as an integrator state ``(Q0, 0, L0_dynamic)``.
    l_rates : ndarray or None, shape (N, m)
        ``Ldot`` (zero for quasi-static pads).
    event_pad : str or None
        The pad of the terminal event.
    """

    status: str
    message: str
    t: np.ndarray
    y: np.ndarray
    l: np.ndarray
    contact: np.ndarray
    energy_terms: np.ndarray
    params: Any
    q0: np.ndarray
    method: str
    rtol: float
    atol: np.ndarray
    t_span: tuple[float, float]
    t_event: float | None = None
    y_event: np.ndarray | None = None
    event_times: dict[str, list[float]] = field(default_factory=dict)
    stats: dict[str, Any] = field(default_factory=dict)
    model: str = "paper"
    record: EstimationRecord | None = None
    modes: LinearModes | None = None
    sample_rate: float = math.nan
    y_start: np.ndarray | None = None
    start: str = ""
    coords: tuple[str, ...] = ("q1", "q2")
    pads: tuple[str, ...] = ("1", "2")
    pad_unknowns: tuple[str, ...] = ()
    dynamic: tuple[str, ...] = ()
    tilting: bool = True
    y_silent: np.ndarray | None = None
    l_rates: np.ndarray | None = None
    event_pad: str | None = None
    contact_law: str = "bilateral"
    engaged: np.ndarray | None = None
    t_final: float = math.nan

    @property
    def t_end_reached(self) -> float:
        """Time [s] at which the integration ended: the end time, the terminal event's time or where it failed.

        Not the last output sample (``t[-1]``), which lies up to one output interval earlier.  A trajectory
        built without :attr:`t_final` (it is set by :func:`~brakesqueal.simulation.simulate`): the terminal
        event's time, else the last output sample.
        """
        if math.isfinite(self.t_final):
            return float(self.t_final)
        if self.t_event is not None:
            return float(self.t_event)
        return float(self.t[-1]) if self.t.size else float(self.t_span[0])

    # ---------------------------------------------------------------- structure
    @property
    def success(self) -> bool:
        """True when the end time was reached."""
        return self.status == "finished"

    @property
    def n(self) -> int:
        """Number of coordinates."""
        return len(self.coords)

    @property
    def silent_state(self) -> np.ndarray:
        """The silent motion as an integrator state ``(Q0, 0, L0_dynamic)``."""
        if self.y_silent is not None:
            return self.y_silent
        return np.concatenate([self.q0, np.zeros(self.y.shape[1] - self.q0.size)])

    @property
    def q_m0(self) -> np.ndarray:
        """Alias of :attr:`q0` (the silent-motion tilt of the paper's model), kept for earlier code."""
        return self.q0

    @property
    def Q(self) -> np.ndarray:
        """Coordinates, shape (N, n)."""
        return self.y[:, : self.n]

    @property
    def Qdot(self) -> np.ndarray:
        """Coordinate rates, shape (N, n)."""
        return self.y[:, self.n : 2 * self.n]

    @property
    def dq(self) -> np.ndarray:
        """Deviation of the coordinates from the silent motion ``Q - Q0``, shape (N, n)."""
        return self.Q - self.q0

    @property
    def normal_forces(self) -> np.ndarray:
        """``F_n`` of every pad [N], shape (N, n_pads) (unilateral contact: the acting force, 0 while lifted off)."""
        return self.contact[:, :, 0]

    @property
    def duty_cycle(self) -> np.ndarray | None:
        """Fraction of the output samples each pad is pressed, shape (n_pads,) (``None`` for bilateral contact)."""
        return None if self.engaged is None else self.engaged.mean(axis=0)

    @property
    def sliding_velocities(self) -> np.ndarray:
        """``v_r`` of every pad [m/s], shape (N, n_pads, 3)."""
        return self.contact[:, :, 1:4]

    @property
    def kinetic(self) -> np.ndarray:
        """``T2, T1, T0`` [J], shape (N, 3): kinetic energy by degree in the tilt rates (earlier layout)."""
        return self.energy_terms[:, :3]

    def energy(self) -> dict[str, np.ndarray]:
        """Energy terms [J] at every sample.

        ``T2, T1, T0`` (kinetic energy with the spin constraint by degree in
        the tilt rates; pads and calipers with mass add to ``T2``),
        ``V_support`` (``k_t (q1^2 + q2^2)/2`` and the calipers' springs),
        ``V_pads`` (per pad ``k (h - w_m)^2/2 - s N0 h``, or with a normal DOF
        ``k (w - w_m)^2/2 - s N0 w + N0 delta + k_c delta^2/2``; tangential
        ``k_ip (l - u_m)^2/2 + mu* N0 l``) and ``E = T2 + V_support + V_pads``.
        Without friction and damping ``E`` is conserved to leading (quadratic)
        order in the tilt, exactly for a non-tilting disk; see
        ``docs/simulation.md``.
        """
        T2, T1, T0, vs, vp = self.energy_terms.T
        return {"T2": T2, "T1": T1, "T0": T0, "V_support": vs, "V_pads": vp, "E": T2 + vs + vp}

    def _radius(self, radius: float | None) -> float:
        if radius is not None:
            return float(radius)
        if "r" in self.params:
            return float(self.params["r"])
        pad = self.params.model.pads[0]
        return float(self.params[pad.radius]) if isinstance(pad.radius, str) else float(pad.radius)

    def rim_velocity(self, radius: float | None = None, azimuth_deg: float = -45.0) -> np.ndarray:
        """Normal (``z0``) velocity [m/s] of the disk's mid-plane under a fixed point of the rim.

        The point is at ``(R cos a, R sin a)`` in the fixed frame (``R`` =
        ``radius``, default the braking radius ``r``, else the first pad's
        radius; the paper's pads are at ``a = -90 deg``).  The mid-plane
        height there is ``z = y tan q1 - x tan q2 / cos q1``.

        Raises
        ------
        ParameterError
            For a model whose disk does not tilt (see :meth:`audio_velocity`).
        """
        from ..errors import ParameterError

        if not self.tilting:
            raise ParameterError(f"model '{self.model}' has a non-tilting disk: no rim velocity (see audio_velocity)")
        R = self._radius(radius)
        a = math.radians(azimuth_deg)
        x, yy = R * math.cos(a), R * math.sin(a)
        n = self.n
        q1, q2, d1, d2 = self.y[:, 0], self.y[:, 1], self.y[:, n], self.y[:, n + 1]
        c1 = np.cos(q1)
        return yy * d1 / c1**2 - x * (d2 / (np.cos(q2) ** 2 * c1) + np.tan(q2) * np.sin(q1) * d1 / c1**2)

    def audio_velocity(self, radius: float | None = None) -> tuple[np.ndarray, str]:
        """The velocity written to audio and what it is.

        A tilting disk: :meth:`rim_velocity` (a microphone or vibrometer at
        the rim).  A non-tilting disk (a belt): the velocity of the first
        pad's tangential coordinate ``u_<pad>`` if there is one, else of the
        first coordinate (a vibrometer on the pad).

        Returns
        -------
        velocity : ndarray, shape (N,)
            [m/s]
        description : str
        """
        if self.tilting:
            return self.rim_velocity(radius), "normal velocity of the disk's mid-plane under the rim at -45 deg"
        j = next((i for i, c in enumerate(self.coords) if c.startswith("u")), 0)
        return self.Qdot[:, j], f"velocity of the coordinate {self.coords[j]} (the disk does not tilt)"

    # ---------------------------------------------------------------- summary
    @cached_property
    def summary(self) -> Summary:
        """Growth rate and frequency of the leading mode with uncertainties, final and limit-cycle amplitude.

        Computed by :func:`summarize` from :attr:`record` (the integrator's
        dense output, independent of ``sample_rate``); without a record,
        from the output grid (with a warning).
        """
        y_s = self.silent_state
        x_start = None if self.y_start is None else self.y_start - y_s
        if self.record is not None:
            t, y = self.record.t, self.record.y
            extra: tuple[str, ...] = ()
        else:
            t, y = self.t, self.y
            extra = ("no estimation record: the summary uses the output samples",)
        fs = self.sample_rate if math.isfinite(self.sample_rate) else None
        s = summarize(self.status, t, y - y_s, self.modes, output_rate=fs, x_start=x_start,
                      integration_error=self.integration_error_bound(t, y - y_s), coordinates=self.n)  # fmt: skip
        soft = self.soft_quasi_static_pads
        if soft and s.regime == "nonlinear":
            extra += (f"pads {', '.join(soft)} are quasi-static (ldot := 0; their k_ip is finite): exact in the "
                      "linear regime, only to first order beyond it; --pad-damping D keeps their rates "
                      "(docs/nonlinear.md)",)
        if extra:
            s = replace(s, warnings=s.warnings + extra)
        return s

    @property
    def soft_quasi_static_pads(self) -> tuple[str, ...]:
        """Pads integrated quasi-statically (``ldot := 0``) although their ``k_ip`` is finite: exact only to
        first order beyond the linear regime (:func:`soft_quasi_static_pads`)."""
        return soft_quasi_static_pads(self.params)

    def integration_error_bound(self, t: np.ndarray, x: np.ndarray) -> float:
        """:func:`integration_error_bound` for this run over the samples ``x`` (deviations) at times ``t``.

        Parameters
        ----------
        t : ndarray, shape (N,)
            Sample times [s].
        x : ndarray, shape (N, 2n + k)
            State deviations from the silent motion.

        Returns
        -------
        float
            Bound [1/s] (0 when the step count is unknown).
        """
        steps = self.stats.get("steps")
        if steps is None:  # solve_ivp: estimate the steps from the RHS evaluations
            steps = self.stats.get("nfev", 0) / _STAGES.get(self.method, 1)
        dur = (float(self.t[-1]) if self.t.size else self.t_span[1]) - self.t_span[0]
        mode = self.modes.left[:, 0] if self.modes is not None else None
        return integration_error_bound(x, x + self.silent_state, self.rtol, self.atol, float(steps), dur, mode)

    @property
    def main_coordinate(self) -> int:
        """Index of the coordinate that carries the motion: the one the plot's phase portrait and spectrum show.

        A tilting disk: the tilt (``q1`` or ``q2``) with the larger RMS deviation from the silent motion over
        the output samples (a mode can move ``q2`` while ``q1`` hardly moves); a non-tilting disk: the
        coordinate with the largest RMS deviation (all displacements [m]).  0 without samples.
        """
        cand = [j for j, c in enumerate(self.coords) if c.startswith("q")] if self.tilting else list(range(self.n))
        if not cand or self.t.size == 0:
            return 0
        d = self.dq[:, cand]
        rms = np.sqrt(np.nanmean(np.where(np.isfinite(d), d, np.nan) ** 2, axis=0))
        return cand[int(np.nanargmax(rms))] if np.any(np.isfinite(rms)) else cand[0]

    def final_amplitudes(self) -> dict[str, float]:
        """``max |Q_j - Q_j0|`` of each coordinate over the last two periods of the output samples.

        The period is that of :attr:`summary`'s frequency (else the last tenth of the record).  Each value is
        in its coordinate's unit (:func:`~brakesqueal.model.components.coordinate_unit`: tilts ``q...`` [rad],
        displacements [m]), unlike :attr:`Summary.amplitude_final`, the norm over all coordinates.

        Returns
        -------
        dict
            Coordinate name -> amplitude (NaN without samples).
        """
        if self.t.size == 0:
            return {c: math.nan for c in self.coords}
        f = self.summary.frequency_hz
        dt = float(self.t[1] - self.t[0]) if self.t.size > 1 else 0.0
        per = int(2 / (f * dt)) if math.isfinite(f) and f > 0 and dt > 0 else self.t.size // 10
        per = max(min(per, self.t.size), 1)
        tail = np.abs(self.dq[-per:])
        return {c: float(np.nanmax(tail[:, j])) if np.any(np.isfinite(tail[:, j])) else math.nan
                for j, c in enumerate(self.coords)}

    @property
    def duration(self) -> float:
        """Simulated time [s]: from the start to :attr:`t_end_reached` (the length of the WAV's signal)."""
        return self.t_end_reached - float(self.t_span[0])

    @property
    def stop_reason(self) -> str:
        """One line: how long the run lasted and why it ended (end time reached, an event, a failure).

        Every output carries it (the CLI's text and JSON, NetCDF ``attrs["stop_reason"]``, the plot), so an
        early stop (e.g. a contact loss with ``events="stop"``) and a short WAV never go unexplained.
        """
        t_req = float(self.t_span[1] - self.t_span[0])
        if self.status == "finished":
            return f"ran the whole {_seconds(t_req)}"
        why = self.message or str(self.status)
        what = "failed" if self.status == "failed" else "stopped early"
        return f"{what} after {_seconds(self.duration)} of {_seconds(t_req)}: {why}"

    def spectrum(self, coordinate: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """Hann-windowed amplitude spectrum of a coordinate's deviation: ``(frequency [Hz], |X|)``.

        Parameters
        ----------
        coordinate : int, optional
            Index of the coordinate (default 0, the first; :attr:`main_coordinate` is the one that carries
            the motion, which :meth:`plot` shows).
        """
        j = int(coordinate)
        x = self.dq[:, j] - self.dq[:, j].mean()
        w = np.hanning(x.size)
        X = np.abs(np.fft.rfft(x * w)) * 2 / w.sum()
        f = np.fft.rfftfreq(x.size, self.t[1] - self.t[0])
        return f, X

    def plot(self, fig: Any = None) -> Any:
        """Time history with its envelope, phase portrait of the last periods, and spectrum.

        The time history shows the tilt deviations (a non-tilting disk: every
        coordinate's); the envelope joins the peaks of the combined deviation
        ``sqrt(sum dq_i^2)`` (no edge effects of a transform); the phase
        portrait shows the last three periods of the squeal frequency (the
        whole record would fill an annulus).  Phase portrait and spectrum show
        the coordinate that carries the motion (:attr:`main_coordinate`: the
        tilt with the larger RMS deviation; a non-tilting disk: the coordinate
        with the largest), named in their titles; every unit is that of its
        coordinate (:func:`~brakesqueal.model.components.coordinate_unit`).
        The title gives the final amplitude of that coordinate and
        :attr:`stop_reason` (how long the run lasted and why it ended).
        Returns the matplotlib ``Figure`` (never calls ``show``), in the
        package's figure style (two journal columns wide).
        """
        import matplotlib
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
        from scipy.signal import find_peaks

        from ..labels import STYLE
        from ..model.components import coordinate_unit

        style: dict[Any, Any] = dict(STYLE)  # rc values of the package's style (matplotlib's stubs want rc keys)
        with matplotlib.rc_context(style):
            if fig is None:
                fig = Figure(figsize=(7.0, 4.4), layout="constrained")
                FigureCanvasAgg(fig)
            gs = fig.add_gridspec(2, 2)
            ax_t = fig.add_subplot(gs[0, :])
            ax_p = fig.add_subplot(gs[1, 0])
            ax_s = fig.add_subplot(gs[1, 1])
            s = self.summary
            cols = [0, 1] if self.tilting else list(range(self.n))
            dq = self.dq[:, cols]
            units = {coordinate_unit(self.coords[j]) for j in cols}
            unit = units.pop() if len(units) == 1 else "rad, m"
            m = self.main_coordinate
            for i, j in enumerate(cols):
                c = self.coords[j]
                ax_t.plot(self.t, dq[:, i], lw=0.5, alpha=1.0 if j == m else 0.7, label=f"{c} − {c}₀")
            r = np.sqrt(np.sum(dq**2, axis=1))
            peaks, _ = find_peaks(r)
            if peaks.size >= 2:
                ax_t.plot(self.t[peaks], r[peaks], "k", lw=0.8, label="envelope")
                ax_t.plot(self.t[peaks], -r[peaks], "k", lw=0.8)
            ax_t.set_xlabel("$t$ [s]")
            ax_t.set_ylabel(f"{'tilt' if self.tilting else 'coordinate'} deviation [{unit}]")
            cm = self.coords[m]
            um = coordinate_unit(cm)
            a = self.final_amplitudes().get(cm, math.nan)
            amp = f"{a:.3g} {um}" if math.isfinite(a) else "n/a"
            ax_t.set_title(
                f"{self.model}: $f$ = {s.frequency_hz:.2f} Hz, growth rate = {s.growth_rate:.4g} 1/s, "
                f"final amplitude of {cm} = {amp}\n{self.stop_reason}", loc="left", wrap=True)
            if self.t_event is not None:
                ax_t.axvline(self.t_event, color="r", ls="--", lw=1, label=str(self.status).replace("-", " "))
            ax_t.legend(loc="lower left", bbox_to_anchor=(1.0, 0.0), frameon=False)
            keep = slice(None)
            if math.isfinite(s.frequency_hz) and s.frequency_hz > 0 and self.t.size >= 2:
                keep = self.t >= self.t[-1] - 3.0 / s.frequency_hz
            ax_p.plot(self.dq[keep, m], self.Qdot[keep, m], lw=0.8)
            ax_p.set_xlabel(f"{cm} − {cm}₀ [{um}]")
            ax_p.set_ylabel(f"d{cm}/d$t$ [{um}/s]")
            ax_p.set_title(f"phase portrait of {cm}, last three periods", loc="left")
            ax_p.ticklabel_format(style="sci", scilimits=(-2, 3))
            if self.t.size >= 16:
                f, X = self.spectrum(m)
                ax_s.semilogy(f, X + 1e-300, lw=0.7)
                if math.isfinite(s.frequency_hz) and s.frequency_hz > 0:
                    ax_s.axvline(s.frequency_hz, color="r", ls="--", lw=1, label=f"squeal {s.frequency_hz:.1f} Hz")
                    ax_s.set_xlim(0, min(f[-1], 4 * s.frequency_hz))
                    ax_s.legend(frameon=False)
            ax_s.set_xlabel("frequency [Hz]")
            ax_s.set_ylabel(f"|{cm}| [{um}]")
            ax_s.set_title(f"spectrum of {cm}", loc="left")
        return fig

    # ---------------------------------------------------------------- export
    def to_xarray(self) -> Any:
        """``xarray.Dataset`` with dims ``time``, ``coord``, ``pad``, ``component``; summary in ``attrs``.

        Variables: ``Q``, ``Qdot`` (``time``, ``coord``), ``Q0`` (``coord``),
        per pad ``F_n``, ``v_r``, ``h``, ``hdot``, ``l`` (tangential position),
        ``energy`` and its terms, ``audio_velocity``; for a tilting disk also
        the earlier keys ``q``, ``dq`` (``time``, ``dof`` = ``q1, q2``),
        ``q_m0`` and ``rim_velocity``; the dynamic pads' states ``L_state``.
        """
        import xarray as xr

        e = self.energy()
        audio, what = self.audio_velocity()
        attrs: dict[str, Any] = {
            "status": str(self.status), "message": self.message, "model": self.model, "method": self.method,
            "rtol": self.rtol, "atol": self.atol.tolist(), "t_start": self.t_span[0], "t_end": self.t_span[1],
            "parameters": json.dumps(self.params.to_json_dict()),
            "t_event": math.nan if self.t_event is None else self.t_event,
            "event_pad": "" if self.event_pad is None else self.event_pad,
            "event_times": json.dumps(self.event_times),
            "pad_treatment": json.dumps({name: ("dynamic" if name in self.dynamic else "quasi-static")
                                         for name in self.pad_unknowns}),
            "audio_velocity": what, "contact_law": self.contact_law,
            "stop_reason": self.stop_reason, "duration_s": self.duration,
        }  # fmt: skip
        for k, v in self.summary.to_dict().items():
            if k == "status":
                continue
            if isinstance(v, dict) or (isinstance(v, list) and any(isinstance(u, str) for u in v)) or k == "warnings":
                attrs[k] = json.dumps(v)
            else:
                attrs[k] = math.nan if v is None else (np.asarray(v, dtype=float) if isinstance(v, list) else v)
        attrs["start"] = self.start
        n = self.n
        c = self.contact
        data: dict[str, Any] = {
            "Q": (("time", "coord"), self.Q, {"long_name": "coordinates (tilts [rad], displacements [m])"}),
            "Qdot": (("time", "coord"), self.Qdot, {"long_name": "coordinate rates"}),
            "F_n": (("time", "pad"), c[:, :, 0], {"units": "N", "long_name": "normal contact force"}),
            "v_r": (("time", "pad", "component"), c[:, :, 1:4],
                    {"units": "m/s", "long_name": "relative sliding velocity"}),
            "h": (("time", "pad"), c[:, :, 4], {"units": "m", "long_name": "height of the contact point"}),
            "hdot": (("time", "pad"), c[:, :, 5], {"units": "m/s", "long_name": "rate of h"}),
            "l": (("time", "pad"), c[:, :, 6], {"units": "m", "long_name": "tangential position of the pad"}),
            "energy": (("time",), e["E"], {"units": "J", "long_name": "E = T2 + V_support + V_pads"}),
            "audio_velocity": (("time",), audio, {"units": "m/s", "long_name": what}),
        }  # fmt: skip
        for k in ("T2", "T1", "T0", "V_support", "V_pads"):
            data[f"energy_{k}"] = (("time",), e[k], {"units": "J"})
        coords: dict[str, Any] = {"time": ("time", self.t, {"units": "s"}), "coord": list(self.coords),
                                  "pad": list(self.pads), "component": ["x0", "y0", "z0"],
                                  "Q0": ("coord", self.q0)}  # fmt: skip
        if self.engaged is not None:
            data["engaged"] = (("time", "pad"), self.engaged.astype(np.int8),
                               {"long_name": "pad pressed (1) or lifted off (0)"})
        if self.dynamic:
            data["L_state"] = (("time", "pad_state"), self.y[:, 2 * n:], {"units": "m"})
            coords["pad_state"] = list(self.dynamic)
        if self.tilting:
            data["q"] = (("time", "dof"), self.y[:, :2], {"units": "rad", "long_name": "tilt angles"})
            data["dq"] = (("time", "dof"), self.y[:, n:n + 2], {"units": "rad/s", "long_name": "tilt rates"})
            data["rim_velocity"] = (("time",), audio, {"units": "m/s", "long_name": "rim normal velocity"})
            coords["dof"] = ["q1", "q2"]
            coords["q_m0"] = ("dof", self.q0[:2], {"units": "rad"})
        return xr.Dataset(data, coords=coords, attrs=attrs)

    def to_netcdf(self, path: str, *, what: str = "NetCDF output") -> None:
        """Write :meth:`to_xarray` to a NetCDF file (netCDF4 engine if installed, else SciPy's NetCDF3).

        The file is written atomically (:func:`brakesqueal.outputs.atomic_write`):
        an interrupted or failed write leaves no partial file and keeps an
        existing file of that name.

        Raises
        ------
        OutputError
            One line when the file cannot be written (``what`` names it).
        """
        from ..outputs import atomic_write

        ds = self.to_xarray()
        ds.attrs["atol"] = json.dumps(ds.attrs["atol"])
        try:
            import netCDF4  # noqa: F401

            engine = "netcdf4"
        except ImportError:
            engine = "scipy"
        with atomic_write(path, what=what) as tmp:
            ds.to_netcdf(tmp, engine=engine)

    def to_wav(self, path: str, *, rate: int = 44100, radius: float | None = None, what: str = "WAV output") -> int:
        """Write :meth:`audio_velocity` as 16-bit mono PCM audio, normalized to 90 % full scale.

        The signal (mean removed) is resampled from the output rate to
        ``rate`` (polyphase filter) and written atomically (see
        :meth:`to_netcdf`).  Returns the number of frames.
        """
        import wave
        from fractions import Fraction

        from scipy.signal import resample_poly

        from ..outputs import atomic_write

        v = self.audio_velocity(radius)[0]
        v = v[np.isfinite(v)]
        v = v - v.mean() if v.size else v
        fs = 1.0 / (self.t[1] - self.t[0]) if self.t.size > 1 else float(rate)
        if v.size > 1 and abs(fs - rate) > 1e-6 * rate:
            fr = Fraction(rate / fs).limit_denominator(1000)
            v = resample_poly(v, fr.numerator, fr.denominator)
        peak = float(np.abs(v).max()) if v.size else 0.0
        pcm = np.zeros(v.size, dtype="<i2") if peak == 0 else np.round(v / peak * 0.9 * 32767).astype("<i2")
        with atomic_write(path, what=what) as tmp:
            with wave.open(str(tmp), "wb") as w:
                w.setnchannels(1)
                w.setsampwidth(2)
                w.setframerate(int(rate))
                w.writeframes(pcm.tobytes())
        return int(pcm.size)


def _seconds(t: float) -> str:
    """A duration for people: ``18 ms``, ``0.2 s``, ``3.5 s``."""
    return f"{1e3 * t:.3g} ms" if abs(t) < 0.1 else f"{t:.4g} s"


def soft_quasi_static_pads(params: Parameters) -> tuple[str, ...]:
    """Pads the simulation treats quasi-statically (``ldot := 0``, :attr:`Pad.treatment
    <brakesqueal.model.components.Pad.treatment>`) although their ``k_ip`` is finite at ``params``: exact only
    to first order beyond the linear regime (``docs/nonlinear.md``).

    Parameters
    ----------
    params : Parameters
        The model and its parameter values.

    Returns
    -------
    tuple of str
        Pad names, in the model's order.
    """
    out = []
    for pad in params.model.pads:
        k = pad.k_ip
        if pad.treatment == "quasi-static" and not math.isinf(float(params[k]) if isinstance(k, str) else float(k)):
            out.append(pad.name)
    return tuple(out)
