r"""The result of :func:`~brakesqueal.simulation.simulate`: samples, summary numbers, plot, export, audio."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from ..parameters import Parameters

__all__ = ["Trajectory", "Summary", "envelope", "fit_growth_frequency"]


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


@dataclass(frozen=True)
class Summary:
    """Summary numbers of a trajectory.

    Attributes
    ----------
    status : str
        ``"finished"``, ``"contact-loss"``, ``"sliding-reversal"`` or ``"failed"``.
    frequency_hz : float
        Dominant frequency [Hz] (slope of the Hilbert phase of the tilt deviation).
    growth_rate : float
        Envelope growth rate [1/s] (least-squares slope of the log Hilbert
        envelope of ``q_m - q_m0`` over the central 80 % of the record).
    amplitude_final : float
        ``max |q_m - q_m0|`` over the last two periods [rad].
    limit_cycle_amplitude : float or None
        Envelope mean over the last quarter when the growth has stopped there
        (|local rate| x quarter length < 0.02) after growing; else ``None``.
    """

    status: str
    frequency_hz: float
    growth_rate: float
    amplitude_final: float
    limit_cycle_amplitude: float | None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (non-finite numbers become ``None``)."""

        def clean(v: Any) -> Any:
            return None if isinstance(v, float) and not math.isfinite(v) else v

        return {k: clean(v) for k, v in self.__dict__.items()}


@dataclass(frozen=True, eq=False)
class Trajectory:
    """A simulated motion of the wobbling disk.

    Attributes
    ----------
    status, message : str
        How the run ended (see :class:`Summary`) and a one-line explanation.
    t : ndarray, shape (n,)
        Uniform output times [s].
    y : ndarray, shape (n, 4)
        ``(q1, q2, dq1, dq2)`` [rad, rad/s].
    l : ndarray, shape (n, 2)
        Tangential pad deformations ``l1, l2`` [m] (quasi-static).
    contact : ndarray, shape (n, 12)
        Per pad ``F_n`` [N], ``v_r`` (3) [m/s], ``h`` [m], ``hdot`` [m/s].
    kinetic : ndarray, shape (n, 3)
        ``T2, T1, T0`` [J]: kinetic energy split by degree in ``q_mdot``.
    params : Parameters
    q_m0 : ndarray, shape (2,)
        Silent-motion tilt [rad].
    method : str
    rtol : float
    atol : ndarray
    t_span : (float, float)
    t_event, y_event : float or None, ndarray or None
        Time and state of the terminal event, if the run stopped at one.
    event_times : dict
        Recorded event times by name (``events="continue"``).
    stats : dict
        ``nfev``, ``wall_s`` and (compiled method) ``steps``, ``rejected``.
    model : str
    """

    status: str
    message: str
    t: np.ndarray
    y: np.ndarray
    l: np.ndarray
    contact: np.ndarray
    kinetic: np.ndarray
    params: Parameters
    q_m0: np.ndarray
    method: str
    rtol: float
    atol: np.ndarray
    t_span: tuple[float, float]
    t_event: float | None = None
    y_event: np.ndarray | None = None
    event_times: dict[str, list[float]] = field(default_factory=dict)
    stats: dict[str, Any] = field(default_factory=dict)
    model: str = "general-2dof"

    @property
    def success(self) -> bool:
        """True when the end time was reached."""
        return self.status == "finished"

    @property
    def dq(self) -> np.ndarray:
        """Tilt deviation from the silent motion ``q_m - q_m0`` [rad], shape (n, 2)."""
        return self.y[:, :2] - self.q_m0

    @property
    def normal_forces(self) -> np.ndarray:
        """``F_n1, F_n2`` [N], shape (n, 2)."""
        return self.contact[:, [0, 6]]

    @property
    def sliding_velocities(self) -> np.ndarray:
        """``v_r`` of both pads [m/s], shape (n, 2, 3)."""
        return np.stack([self.contact[:, 1:4], self.contact[:, 7:10]], axis=1)

    def energy(self) -> dict[str, np.ndarray]:
        """Energy terms [J] at every sample.

        ``T2, T1, T0`` (kinetic energy with the spin constraint, by degree in
        ``q_mdot``), ``V_support = k_t (q1^2 + q2^2)/2``, ``V_pads = sum_i
        k_i h_i^2/2 - s_i N0 h_i + l_i^2/(2 c_ip_i)`` (``s = +1, -1``) and the
        tilt energy ``E = T2 + V_support + V_pads``.  Without friction and
        damping ``E`` is conserved to leading (quadratic) order in the tilt;
        the exact energy balance and why no exact integral exists for the
        modelled supports are derived in ``docs/simulation.md``.
        """
        p = self.params
        q = self.y[:, :2]
        h1, h2 = self.contact[:, 4], self.contact[:, 10]
        c1, c2 = p.compliances()
        vs = 0.5 * p.k_t * (q[:, 0] ** 2 + q[:, 1] ** 2)
        vp = 0.5 * p.k1 * h1**2 - p.N0 * h1 + 0.5 * p.k2 * h2**2 + p.N0 * h2
        if c1 > 0:
            vp = vp + 0.5 * self.l[:, 0] ** 2 / c1
        if c2 > 0:
            vp = vp + 0.5 * self.l[:, 1] ** 2 / c2
        T2, T1, T0 = self.kinetic.T
        return {"T2": T2, "T1": T1, "T0": T0, "V_support": vs, "V_pads": vp, "E": T2 + vs + vp}

    def rim_velocity(self, radius: float | None = None, azimuth_deg: float = -45.0) -> np.ndarray:
        """Normal (``z0``) velocity [m/s] of the disk's mid-plane under a fixed point of the rim.

        The point is at ``(R cos a, R sin a)`` in the fixed frame (``R`` =
        ``radius``, default the braking radius ``r``; the pads are at
        ``a = -90 deg``).  The mid-plane height there is
        ``z = y tan q1 - x tan q2 / cos q1``.
        """
        R = self.params.r if radius is None else float(radius)
        a = math.radians(azimuth_deg)
        x, yy = R * math.cos(a), R * math.sin(a)
        q1, q2, d1, d2 = self.y.T
        c1 = np.cos(q1)
        return yy * d1 / c1**2 - x * (d2 / (np.cos(q2) ** 2 * c1) + np.tan(q2) * np.sin(q1) * d1 / c1**2)

    @cached_property
    def summary(self) -> Summary:
        """Dominant frequency, growth rate, final and limit-cycle amplitude."""
        n = self.t.size
        nan = math.nan
        if n < 16:
            return Summary(self.status, nan, nan, nan if n == 0 else float(np.abs(self.dq).max()), None)
        dq = self.dq
        growth, freq = fit_growth_frequency(self.t, dq)
        fs = 1.0 / (self.t[1] - self.t[0])
        per = int(2 * fs / freq) if freq > 0 else n // 10
        per = max(min(per, n), 2)
        amp = float(np.sqrt((dq[-per:] ** 2).sum(axis=1)).max())
        lc = None
        if self.status == "finished" and n > 400:
            env, _ = envelope(dq)
            q = n // 4
            seg_t, seg = self.t[-q - n // 20 : -n // 20], env[-q - n // 20 : -n // 20]
            local = float(np.polyfit(seg_t, np.log(seg), 1)[0])
            if abs(local) * (seg_t[-1] - seg_t[0]) < 0.02 and env[n // 10] < 0.9 * seg.mean():
                lc = float(seg.mean())
        return Summary(self.status, freq, growth, amp, lc)

    def spectrum(self) -> tuple[np.ndarray, np.ndarray]:
        """Hann-windowed amplitude spectrum of ``q1 - q10``: ``(frequency [Hz], |X|)``."""
        x = self.dq[:, 0] - self.dq[:, 0].mean()
        w = np.hanning(x.size)
        X = np.abs(np.fft.rfft(x * w)) * 2 / w.sum()
        f = np.fft.rfftfreq(x.size, self.t[1] - self.t[0])
        return f, X

    def plot(self, fig: Any = None) -> Any:
        """Time history with envelope, phase portrait and spectrum (squeal frequency marked).

        Returns the matplotlib ``Figure`` (never calls ``show``).
        """
        import matplotlib.pyplot as plt

        if fig is None:
            fig = plt.figure(figsize=(11, 7), layout="constrained")
        gs = fig.add_gridspec(2, 2)
        ax_t = fig.add_subplot(gs[0, :])
        ax_p = fig.add_subplot(gs[1, 0])
        ax_s = fig.add_subplot(gs[1, 1])
        s = self.summary
        dq = self.dq
        ax_t.plot(self.t, dq[:, 0], lw=0.5, label=r"$q_1 - q_{10}$")
        ax_t.plot(self.t, dq[:, 1], lw=0.5, alpha=0.7, label=r"$q_2 - q_{20}$")
        if self.t.size >= 16:
            env, _ = envelope(dq)
            ax_t.plot(self.t, env, "k", lw=1, label="envelope")
            ax_t.plot(self.t, -env, "k", lw=1)
        ax_t.set_xlabel("t [s]")
        ax_t.set_ylabel("tilt deviation [rad]")
        ax_t.set_title(
            f"{self.status}: f = {s.frequency_hz:.2f} Hz, growth = {s.growth_rate:.4g} 1/s, "
            f"final amplitude = {s.amplitude_final:.3g} rad"
        )
        if self.t_event is not None:
            ax_t.axvline(self.t_event, color="r", ls="--", lw=1, label=self.status)
        ax_t.legend(loc="upper left", fontsize=8)
        ax_p.plot(dq[:, 0], self.y[:, 2], lw=0.3)
        ax_p.set_xlabel(r"$q_1 - q_{10}$ [rad]")
        ax_p.set_ylabel(r"$\dot q_1$ [rad/s]")
        ax_p.set_title("phase portrait")
        if self.t.size >= 16:
            f, X = self.spectrum()
            ax_s.semilogy(f, X + 1e-300, lw=0.7)
            if math.isfinite(s.frequency_hz):
                ax_s.axvline(s.frequency_hz, color="r", ls="--", lw=1, label=f"squeal {s.frequency_hz:.1f} Hz")
                ax_s.set_xlim(0, min(f[-1], 4 * s.frequency_hz))
                ax_s.legend(fontsize=8)
        ax_s.set_xlabel("frequency [Hz]")
        ax_s.set_ylabel(r"$|Q_1|$ [rad]")
        ax_s.set_title("spectrum")
        return fig

    def to_xarray(self) -> Any:
        """``xarray.Dataset`` with dims ``time``, ``dof``, ``pad``, ``component``; summary in ``attrs``."""
        import xarray as xr

        vr = self.sliding_velocities
        e = self.energy()
        attrs: dict[str, Any] = {
            "status": self.status, "message": self.message, "model": self.model, "method": self.method,
            "rtol": self.rtol, "atol": self.atol.tolist(), "t_start": self.t_span[0], "t_end": self.t_span[1],
            "parameters": json.dumps(self.params.to_json_dict()),
            "t_event": math.nan if self.t_event is None else self.t_event,
            "event_times": json.dumps(self.event_times),
            "pad_treatment": "quasi-static massless pads: ldot = 0, g(q, qdot, l, 0) = 0",
        }  # fmt: skip
        attrs.update({k: (math.nan if v is None else v) for k, v in self.summary.to_dict().items() if k != "status"})
        ds = xr.Dataset(
            {
                "q": (("time", "dof"), self.y[:, :2], {"units": "rad", "long_name": "tilt angles"}),
                "dq": (("time", "dof"), self.y[:, 2:], {"units": "rad/s", "long_name": "tilt rates"}),
                "l": (("time", "pad"), self.l, {"units": "m", "long_name": "tangential pad deformation"}),
                "F_n": (("time", "pad"), self.normal_forces, {"units": "N", "long_name": "normal contact force"}),
                "v_r": (("time", "pad", "component"), vr, {"units": "m/s", "long_name": "relative sliding velocity"}),
                "h": (("time", "pad"), self.contact[:, [4, 10]], {"units": "m", "long_name": "pad normal displacement"}),
                "rim_velocity": (("time",), self.rim_velocity(), {"units": "m/s", "long_name": "rim normal velocity"}),
                "energy": (("time",), e["E"], {"units": "J", "long_name": "tilt energy T2 + V"}),
            },
            coords={"time": ("time", self.t, {"units": "s"}), "dof": ["q1", "q2"], "pad": [1, 2],
                    "component": ["x0", "y0", "z0"], "q_m0": ("dof", self.q_m0, {"units": "rad"})},  # fmt: skip
            attrs=attrs,
        )
        return ds

    def to_netcdf(self, path: str) -> None:
        """Write :meth:`to_xarray` to a NetCDF file (netCDF4 engine if installed, else SciPy's NetCDF3)."""
        ds = self.to_xarray()
        ds.attrs["atol"] = json.dumps(ds.attrs["atol"])
        try:
            import netCDF4  # noqa: F401

            engine = "netcdf4"
        except ImportError:
            engine = "scipy"
        ds.to_netcdf(path, engine=engine)

    def to_wav(self, path: str, *, rate: int = 44100, radius: float | None = None) -> int:
        """Write the rim's normal velocity as 16-bit mono PCM audio, normalized to 90 % full scale.

        The signal (:meth:`rim_velocity`, mean removed) is resampled from the
        output rate to ``rate`` (polyphase filter).  Returns the number of frames.
        """
        import wave
        from fractions import Fraction

        from scipy.signal import resample_poly

        v = self.rim_velocity(radius)
        v = v[np.isfinite(v)]
        v = v - v.mean() if v.size else v
        fs = 1.0 / (self.t[1] - self.t[0]) if self.t.size > 1 else float(rate)
        if v.size > 1 and abs(fs - rate) > 1e-6 * rate:
            fr = Fraction(rate / fs).limit_denominator(1000)
            v = resample_poly(v, fr.numerator, fr.denominator)
        peak = float(np.abs(v).max()) if v.size else 0.0
        pcm = np.zeros(v.size, dtype="<i2") if peak == 0 else np.round(v / peak * 0.9 * 32767).astype("<i2")
        with wave.open(str(path), "wb") as w:
            w.setnchannels(1)
            w.setsampwidth(2)
            w.setframerate(int(rate))
            w.writeframes(pcm.tobytes())
        return int(pcm.size)
