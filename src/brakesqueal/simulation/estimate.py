r"""Growth rate and frequency of one mode from a sampled motion, with an uncertainty (arrays only).

The functions here know nothing about the brake model: they take sample
times, the state deviation from an equilibrium ``x(t) = X(t) - X0`` (shape
``(N, 2n)``: ``n`` coordinates, then their ``n`` rates) and, when available,
the first-order state matrix ``A`` of the linearization (eq. 47,
``xdot = A x``).

Two estimators:

* :func:`modal_projection` (needs ``A``): the modal coordinate of mode ``k``
  is ``z_k(t) = w_k^H x(t)`` with ``w_k`` the left eigenvector of ``A``
  normalized so that ``w_k^H v_k = 1`` (``v_k`` the right eigenvector).
  Left and right eigenvectors of distinct eigenvalues are biorthogonal
  (``w_k^H v_j = 0``), so for a motion of the linear system
  ``x = sum_j c_j v_j exp(lambda_j t)`` the projection removes every other
  mode (including the complex conjugate of mode ``k``) exactly:
  ``z_k = c_k exp(lambda_k t)``.  ``log|z_k|`` and ``arg z_k`` are then
  fitted by straight lines (:func:`fit_modal_coordinate`), whose slopes are
  ``Re lambda`` and ``Im lambda``.  Beating with other modes does not bias
  the result, and the projection is made sample by sample, so only the phase
  fit needs a sampling rate of more than two samples per period (the phase is
  first demodulated with the linear ``Im lambda_k``, so that even this only
  limits how far the measured frequency may move from the linear one).
* :func:`matrix_pencil` / :func:`dominant_mode` (no model needed): the
  samples are fitted by a sum of damped complex exponentials with the matrix
  pencil method (Hua & Sarkar 1990, IEEE Trans. ASSP 38(5) 814-824), all
  channels sharing the poles; the mode with the largest amplitude at the end
  of the window is reported.  It needs uniform samples above the Nyquist rate
  of every mode present.

Validity: both estimate *exponential* (linear) behaviour.  In the nonlinear
regime the result is an average over the window of an amplitude-dependent
growth rate and frequency; the uncertainty grows accordingly, because it
includes the disagreement between the two halves of the window (see
:func:`fit_modal_coordinate`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from ..errors import ParameterError

__all__ = [
    "LinearModes", "ModalFit", "ModeEstimate", "PencilModes", "linear_modes", "modal_coordinate",
    "fit_modal_coordinate", "modal_projection", "matrix_pencil", "dominant_mode", "points_per_period",
]  # fmt: skip

#: Relative threshold below which samples of ``|z|`` are left out of the fit (noise floor of the integration).
AMPLITUDE_FLOOR = 1e-7


@dataclass(frozen=True)
class LinearModes:
    """Eigenvalues and biorthonormal eigenvectors of a first-order state matrix ``A``.

    Attributes
    ----------
    eigenvalues : ndarray, shape (m,)
        Eigenvalues [1/s], sorted by decreasing real part, then decreasing
        imaginary part; index 0 is the leading (least stable) mode, with
        ``Im >= 0`` when it is one of a complex pair.
    right : ndarray, shape (m, m)
        Right eigenvectors ``v_k`` (columns), ``A v_k = lambda_k v_k``,
        scaled so that the largest of the first ``m/2`` components (the
        coordinates) is 1.
    left : ndarray, shape (m, m)
        Left eigenvectors ``w_k`` (columns), ``w_k^H A = lambda_k w_k^H``,
        scaled so that ``w_k^H v_k = 1``.
    """

    eigenvalues: np.ndarray
    right: np.ndarray
    left: np.ndarray

    @property
    def leading(self) -> complex:
        """The leading eigenvalue ``eigenvalues[0]`` [1/s]."""
        return complex(self.eigenvalues[0])

    @property
    def frequencies_hz(self) -> np.ndarray:
        """``|Im lambda_k| / 2 pi`` [Hz] of every eigenvalue."""
        return np.abs(self.eigenvalues.imag) / (2 * math.pi)

    def start_vector(self, amplitude: float, index: int = 0) -> np.ndarray:
        """Real state deviation ``amplitude * Re(v_k)`` along mode ``k`` (a single mode and its conjugate).

        Parameters
        ----------
        amplitude : float
            Largest coordinate of the returned deviation (``right`` is scaled
            so that its largest coordinate is 1).
        index : int, optional
            Mode index (default 0, the leading mode).

        Returns
        -------
        ndarray, shape (m,)
            ``(dq, dqdot)`` with ``max |dq| = amplitude``.
        """
        v = np.real(self.right[:, index])
        n = v.size // 2
        s = float(np.abs(v[:n]).max()) if n else 1.0
        return amplitude * v / (s if s > 0 else 1.0)


def linear_modes(A: np.ndarray) -> LinearModes:
    """Eigen-decomposition of a first-order state matrix with biorthonormal left and right eigenvectors.

    Parameters
    ----------
    A : ndarray, shape (m, m)
        State matrix for ``x = (dq, dqdot)`` (eq. 47), real.

    Returns
    -------
    LinearModes
        Sorted eigenvalues, right eigenvectors and left eigenvectors with
        ``w_k^H v_k = 1``.

    Raises
    ------
    ParameterError
        If ``A`` is not a finite square matrix or is defective at the leading
        eigenvalue (``w_0^H v_0 = 0``).
    """
    from scipy.linalg import eig

    A = np.asarray(A, dtype=float)
    if A.ndim != 2 or A.shape[0] != A.shape[1] or not np.all(np.isfinite(A)):
        raise ParameterError(f"the state matrix must be a finite square matrix; got shape {A.shape}")
    lam, vl, vr = eig(A, left=True, right=True)
    order = np.lexsort((-lam.imag, -lam.real))
    lam, vl, vr = lam[order], vl[:, order], vr[:, order]
    m = lam.size
    n = max(m // 2, 1)
    for k in range(m):
        j = int(np.argmax(np.abs(vr[:n, k])))
        if abs(vr[j, k]) <= 1e-12 * np.abs(vr[:, k]).max():  # no coordinate part (not a second-order form)
            j = int(np.argmax(np.abs(vr[:, k])))
        vr[:, k] = vr[:, k] / vr[j, k]
        d = np.vdot(vl[:, k], vr[:, k])
        if abs(d) < 1e-12 * np.linalg.norm(vl[:, k]) * np.linalg.norm(vr[:, k]):
            if k == 0:
                raise ParameterError("the state matrix is defective at its leading eigenvalue; no modal projection")
            continue
        vl[:, k] = vl[:, k] / np.conj(d)
    return LinearModes(lam, vr, vl)


def points_per_period(frequency_hz: float, rate_hz: float) -> float:
    """Samples per period of a frequency at a sampling rate (``inf`` for a zero frequency).

    Parameters
    ----------
    frequency_hz : float
        Frequency [Hz].
    rate_hz : float
        Sampling rate [Hz].

    Returns
    -------
    float
        ``rate_hz / |frequency_hz|``; below 2 the frequency is aliased.
    """
    f = abs(float(frequency_hz))
    return math.inf if f == 0 else float(rate_hz) / f


@dataclass(frozen=True)
class ModeEstimate:
    """Growth rate and frequency of one mode estimated from samples.

    Attributes
    ----------
    growth_rate : float
        ``Re lambda`` [1/s] (NaN when it cannot be estimated).
    growth_rate_stderr : float
        Its uncertainty [1/s]: the larger of the regression standard error
        (corrected for correlated residuals) and half the difference between
        the estimates on the two halves of the window.
    frequency_hz : float
        ``Im lambda / 2 pi`` [Hz].
    frequency_stderr : float
        Its uncertainty [Hz], defined as for the growth rate.
    estimator : str
        ``"modal-projection"`` or ``"matrix-pencil"``.
    window : (float, float)
        First and last sample time used [s].
    n_samples : int
        Number of samples used.
    rate_hz : float
        Sampling rate of the samples used [Hz].
    share : float
        Fraction of the coordinate part of the motion (RMS over the last
        tenth of the window) carried by this mode; near 1 when it dominates.
    residual : float
        Relative RMS misfit of the exponential model over the window
        (``|z - z_fit| / |z|``, weighted as in the fit).
    eigenvalue_linear : complex or None
        The linear model's eigenvalue of this mode, when one was given.
    warnings : tuple of str
        Conditions under which the estimate is doubtful (coarse sampling,
        a mode that does not dominate, a poor fit).
    """

    growth_rate: float
    growth_rate_stderr: float
    frequency_hz: float
    frequency_stderr: float
    estimator: str
    window: tuple[float, float]
    n_samples: int
    rate_hz: float
    share: float
    residual: float
    eigenvalue_linear: complex | None = None
    warnings: tuple[str, ...] = field(default_factory=tuple)

    @property
    def eigenvalue(self) -> complex:
        """``growth_rate + 2 pi i frequency_hz`` [1/s]."""
        return complex(self.growth_rate, 2 * math.pi * self.frequency_hz)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (non-finite numbers become ``None``, the linear eigenvalue ``[re, im]``)."""

        def clean(v: Any) -> Any:
            if isinstance(v, float) and not math.isfinite(v):
                return None
            if isinstance(v, complex):
                return [clean(v.real), clean(v.imag)]
            if isinstance(v, tuple):
                return [clean(u) for u in v]
            return v

        return {k: clean(v) for k, v in self.__dict__.items()}


def _nan_estimate(estimator: str, t: np.ndarray, why: str, lam: complex | None = None) -> ModeEstimate:
    w = (float(t[0]), float(t[-1])) if t.size else (math.nan, math.nan)
    return ModeEstimate(math.nan, math.nan, math.nan, math.nan, estimator, w, int(t.size), math.nan, math.nan,
                        math.nan, lam, (why,))  # fmt: skip


def _check_samples(t: Any, x: Any) -> tuple[np.ndarray, np.ndarray]:
    t = np.asarray(t, dtype=float).ravel()
    x = np.asarray(x)
    if x.ndim == 1:
        x = x[:, None]
    if x.ndim != 2 or x.shape[0] != t.size:
        raise ParameterError(f"the samples must have shape (len(t), k); got {x.shape} for {t.size} times")
    if t.size > 1 and not np.all(np.diff(t) > 0):
        raise ParameterError("the sample times must be strictly increasing")
    return t, x


def _wls_line(t: np.ndarray, y: np.ndarray, w: np.ndarray) -> tuple[float, float, float, np.ndarray]:
    """Weighted straight-line fit: slope, intercept, standard error of the slope, residuals.

    ``w`` are relative inverse variances.  The standard error is multiplied
    by ``sqrt((1 + rho)/(1 - rho))`` (AR(1) model of the residuals, ``rho``
    the lag-one autocorrelation of ``sqrt(w) r``), limited so that at least
    three independent samples remain; correlated residuals (a smooth misfit)
    thus do not make the error look small.
    """
    sw = w.sum()
    tm = float((w * t).sum() / sw)
    ym = float((w * y).sum() / sw)
    dt = t - tm
    sxx = float((w * dt * dt).sum())
    slope = float((w * dt * (y - ym)).sum() / sxx)
    icpt = ym - slope * tm
    r = y - (icpt + slope * t)
    n = t.size
    s2 = float((w * r * r).sum()) / max(n - 2, 1)
    u = np.sqrt(w) * r
    uu = float((u * u).sum())
    rho = float((u[:-1] * u[1:]).sum() / uu) if uu > 0 else 0.0
    infl = 1.0 if rho <= 0 else min((1 + rho) / max(1 - rho, 1e-300), n / 3.0)
    se = math.sqrt(max(s2, 0.0) / sxx * max(infl, 1.0))
    return slope, icpt, se, r


def _fit_log_phase(t: np.ndarray, la: np.ndarray, ph: np.ndarray, w: np.ndarray) -> tuple[float, ...]:
    g, gi, gse, _ = _wls_line(t, la, w)
    o, oi, ose, _ = _wls_line(t, ph, w)
    return g, gi, gse, o, oi, ose


class ModalFit(NamedTuple):
    """Result of :func:`fit_modal_coordinate`.

    Attributes
    ----------
    growth, growth_err : float
        ``Re lambda`` and its uncertainty [1/s].
    omega, omega_err : float
        ``Im lambda`` and its uncertainty [rad/s].
    residual : float
        Relative weighted RMS misfit ``sqrt(sum w |z/z_fit - 1|^2 / sum w)``.
    used : ndarray of bool
        The samples used.
    """

    growth: float
    growth_err: float
    omega: float
    omega_err: float
    residual: float
    used: np.ndarray


def fit_modal_coordinate(
    t: np.ndarray, z: np.ndarray, *, omega_ref: float = 0.0, floor: float = AMPLITUDE_FLOOR
) -> ModalFit:
    r"""Fit ``z(t) = c exp(lambda t)`` to a complex modal coordinate: growth, frequency and their errors.

    ``log|z|`` and the unwrapped ``arg z`` are fitted by straight lines with
    weighted least squares, weights ``|z|^2`` (the inverse variance of
    ``log|z|`` and ``arg z`` for noise of constant size added to ``z``).
    Samples with ``|z| < floor max|z|`` are left out.  Before unwrapping,
    ``z`` is multiplied by ``exp(-i omega_ref t)`` and ``omega_ref`` is added
    back to the slope: the unwrap then only has to follow the difference
    from the reference frequency (pass the linear ``Im lambda``).

    The uncertainty of each slope is the larger of

    * the regression standard error, inflated for correlated residuals
      (AR(1) model, see ``_wls_line``), and
    * half the difference between the slopes fitted on the first and the
      second half of the samples (a drift of the growth rate or frequency
      over the window, e.g. by nonlinearity, shows up here).

    Parameters
    ----------
    t : ndarray, shape (N,)
        Sample times [s], increasing.
    z : ndarray, shape (N,), complex
        Modal coordinate.
    omega_ref : float, optional
        Reference angular frequency [rad/s] for the demodulation (default 0).
    floor : float, optional
        Relative amplitude below which samples are ignored (default 1e-7).

    Returns
    -------
    ModalFit
        All numbers are NaN when fewer than 8 samples remain.
    """
    t = np.asarray(t, dtype=float).ravel()
    z = np.asarray(z, dtype=complex).ravel()
    a = np.abs(z)
    fin = np.isfinite(a)
    amax = float(a[fin].max()) if fin.any() else 0.0
    used = fin & (a > floor * amax) if amax > 0 else np.zeros(t.size, bool)
    nan = math.nan
    if used.sum() < 8:
        return ModalFit(nan, nan, nan, nan, nan, used)
    tt, zz = t[used], z[used] * np.exp(-1j * omega_ref * (t[used] - t[used][0]))
    la = np.log(np.abs(zz))
    ph = np.unwrap(np.angle(zz))
    w = (np.abs(zz) / np.abs(zz).max()) ** 2
    g, gi, gse, o, oi, ose = _fit_log_phase(tt, la, ph, w)
    rel = zz / np.exp(gi + g * tt + 1j * (oi + o * tt)) - 1.0
    residual = float(math.sqrt((w * np.abs(rel) ** 2).sum() / w.sum()))
    h = tt.size // 2
    if h >= 4 and tt.size - h >= 4:
        g1, _, _, o1, _, _ = _fit_log_phase(tt[:h], la[:h], ph[:h], w[:h] / w[:h].max())
        g2, _, _, o2, _, _ = _fit_log_phase(tt[h:], la[h:], ph[h:], w[h:] / w[h:].max())
        gse = max(gse, abs(g1 - g2) / 2)
        ose = max(ose, abs(o1 - o2) / 2)
    return ModalFit(g, gse, o + omega_ref, ose, residual, used)


def modal_coordinate(x: np.ndarray, modes: LinearModes, index: int = 0) -> np.ndarray:
    """Modal coordinate ``z_k = w_k^H x`` of every sample.

    Parameters
    ----------
    x : ndarray, shape (N, m)
        State deviations ``(dq, dqdot)`` from the equilibrium, one per row.
    modes : LinearModes
        Eigen-decomposition of the state matrix (:func:`linear_modes`).
    index : int, optional
        Mode index (default 0, the leading mode).

    Returns
    -------
    ndarray, shape (N,), complex
        ``z_k(t)``; the mode's part of the motion is ``2 Re(z_k v_k)`` for a
        complex mode (``z_k v_k`` for a real one).
    """
    x = np.asarray(x, dtype=float)
    return x @ np.conj(modes.left[:, index])


def _share(x: np.ndarray, part: np.ndarray, coordinates: int | None = None) -> float:
    """RMS of ``part`` over RMS of ``x`` (last tenth of the samples) over the displacement-like components.

    Those are the first ``n`` columns (coordinates; default ``n`` = half of
    them) and, when ``coordinates`` is given, the columns after ``2n`` (first-order
    pad states), not the rates.
    """
    n = coordinates if coordinates else max(x.shape[1] // 2, 1)
    cols = np.r_[0:n, 2 * n:x.shape[1]] if coordinates else np.arange(n)
    k = max(x.shape[0] // 10, 1)
    den = float(np.sqrt((x[-k:][:, cols] ** 2).sum()))
    return float(np.sqrt((part[-k:][:, cols] ** 2).sum())) / den if den > 0 else math.nan


def modal_projection(t: np.ndarray, x: np.ndarray, modes: LinearModes, index: int = 0, *,
                     coordinates: int | None = None) -> ModeEstimate:
    """Growth rate and frequency of mode ``index`` by projection onto its left eigenvector.

    Parameters
    ----------
    t : ndarray, shape (N,)
        Sample times [s] (need not be uniform).
    x : ndarray, shape (N, m)
        State deviations ``(dq, dqdot)`` from the equilibrium.
    modes : LinearModes
        Eigen-decomposition of the linear model's state matrix.
    index : int, optional
        Mode (default 0, the leading mode).
    coordinates : int, optional
        Number of coordinates ``n`` among the components of ``x`` (default
        half of them), for the mode's share of the motion; components after
        the ``2n`` coordinates and rates (first-order pad states) count too.

    Returns
    -------
    ModeEstimate
        ``estimator = "modal-projection"``.  Warnings are added when the
        samples are fewer than four per period of the mode, when the mode
        carries less than half of the motion at the end of the window, or
        when the exponential fit leaves more than 10 % misfit.

    Raises
    ------
    ParameterError
        If the shapes do not match or the times do not increase.
    """
    t, x = _check_samples(t, x)
    lam = complex(modes.eigenvalues[index])
    if x.shape[1] != modes.left.shape[0]:
        raise ParameterError(f"the state has {x.shape[1]} components but the state matrix {modes.left.shape[0]}")
    if t.size < 8:
        return _nan_estimate("modal-projection", t, "fewer than 8 samples", lam)
    z = modal_coordinate(x, modes, index)
    g, gse, om, ose, res, used = fit_modal_coordinate(t, z, omega_ref=lam.imag)
    if not used.any():
        return _nan_estimate("modal-projection", t, "the mode is not present in the motion", lam)
    dt = np.diff(t)
    rate = 1.0 / float(np.median(dt))
    warns: list[str] = []
    ppp = points_per_period(max(abs(lam.imag), abs(om) if math.isfinite(om) else 0.0) / (2 * math.pi), rate)
    if ppp < 4:
        warns.append(f"only {ppp:.3g} samples per period of the mode: its frequency may be aliased")
    part = 2 * np.real(np.outer(z, modes.right[:, index])) if lam.imag != 0 else np.real(
        np.outer(z, modes.right[:, index]))  # fmt: skip
    share = _share(x, part, coordinates)
    if math.isfinite(share) and share < 0.5:
        warns.append(f"the mode carries only {100 * share:.3g} % of the motion at the end of the window")
    if math.isfinite(res) and res > 0.1:
        warns.append(f"a single exponential leaves {100 * res:.3g} % misfit: growth rate and frequency vary")
    tu = t[used]
    return ModeEstimate(g, gse, om / (2 * math.pi), ose / (2 * math.pi), "modal-projection",
                        (float(tu[0]), float(tu[-1])), int(used.sum()), rate, share, res, lam,
                        tuple(warns))  # fmt: skip


@dataclass(frozen=True)
class PencilModes:
    """Damped complex exponentials fitted to uniform samples by the matrix pencil method.

    Attributes
    ----------
    eigenvalues : ndarray, shape (r,)
        Continuous-time poles ``lambda_k`` [1/s] (imaginary parts within the
        Nyquist band ``|Im| < pi / dt``).
    amplitudes : ndarray, shape (r, k), complex
        Amplitude of each pole in each channel at the first sample:
        ``x(t_i) ~ sum_k amplitudes[k] exp(lambda_k (t_i - t_0))``.
    singular_values : ndarray
        Singular values of the stacked Hankel matrix (for the order choice).
    t0, dt : float
        First sample time and sampling interval [s].
    n_samples : int
        Number of samples fitted.
    """

    eigenvalues: np.ndarray
    amplitudes: np.ndarray
    singular_values: np.ndarray
    t0: float
    dt: float
    n_samples: int

    def size_at(self, t: float) -> np.ndarray:
        """Euclidean amplitude of every pole at time ``t`` [units of the samples].

        Parameters
        ----------
        t : float
            Time [s].

        Returns
        -------
        ndarray, shape (r,)
            ``|amplitudes[k]| |exp(lambda_k (t - t0))|``.
        """
        return np.linalg.norm(self.amplitudes, axis=1) * np.exp(self.eigenvalues.real * (t - self.t0))


def matrix_pencil(
    t: np.ndarray, x: np.ndarray, *, order: int | None = None, pencil: int | None = None,
    rcond: float = 1e-10, max_order: int = 24,
) -> PencilModes:  # fmt: skip
    """Fit a sum of damped exponentials to uniformly sampled (multi-channel) data: matrix pencil method.

    The Hankel matrices of all channels (``N - L`` rows, ``L + 1`` columns)
    are stacked; the ``r`` leading right singular vectors span the signal
    space, and the eigenvalues ``mu_k`` of the pencil of their shifted parts
    are ``exp(lambda_k dt)`` (Hua & Sarkar 1990).  Amplitudes follow by linear
    least squares on the Vandermonde matrix.

    Parameters
    ----------
    t : ndarray, shape (N,)
        Uniform sample times [s].
    x : ndarray, shape (N,) or (N, k)
        Real or complex samples, one channel per column.
    order : int, optional
        Number of exponentials ``r``.  Default: at the largest ratio of
        consecutive singular values among those larger than
        ``max(rcond s_0, 10 median(s))`` (the median estimates the noise
        floor), at most ``max_order``.
    pencil : int, optional
        Pencil parameter ``L`` (default ``N // 3``).
    rcond : float, optional
        Relative singular-value threshold of the default order (1e-10).
    max_order : int, optional
        Largest default order (24).

    Returns
    -------
    PencilModes
        Poles and amplitudes.

    Raises
    ------
    ParameterError
        If the samples are not uniform, fewer than 8, or the order does not
        fit the pencil.
    """
    t, x = _check_samples(t, x)
    N = t.size
    if N < 8:
        raise ParameterError(f"the matrix pencil needs at least 8 samples; got {N}")
    dt = float((t[-1] - t[0]) / (N - 1))
    if np.abs(np.diff(t) - dt).max() > 1e-6 * dt:
        raise ParameterError("the matrix pencil needs uniformly spaced samples")
    L = int(pencil) if pencil is not None else N // 3
    if not 2 <= L <= N - 2:
        raise ParameterError(f"the pencil parameter must be in [2, {N - 2}]; got {L}")
    cols = [np.lib.stride_tricks.sliding_window_view(x[:, c], L + 1) for c in range(x.shape[1])]
    H = np.concatenate(cols, axis=0)
    scale = float(np.abs(H).max())
    if scale == 0:
        raise ParameterError("the samples are all zero")
    H = H / scale
    if H.shape[0] > H.shape[1]:  # same singular values and right vectors, cheaper: SVD of the QR factor R
        H = np.asarray(np.linalg.qr(H, mode="r"))
    _, s, Vh = np.linalg.svd(H, full_matrices=False)
    if order is None:
        thr = max(rcond * s[0], 10.0 * float(np.median(s)))
        m = min(max(int(np.count_nonzero(s > thr)), 1), max_order, L)
        nxt = np.append(s[1 : m + 1], thr)[:m] if m < s.size else np.append(s[1:m], thr)
        r = int(np.argmax(s[:m] / np.maximum(nxt, 1e-300))) + 1  # at the largest gap of the singular values
    else:
        r = int(order)
        if not 1 <= r <= L:
            raise ParameterError(f"the order must be in [1, {L}]; got {order}")
    V = Vh[:r].conj().T  # (L+1, r)
    mu = np.linalg.eigvals(np.linalg.pinv(V[:-1]) @ V[1:])
    # poles whose exponential overflows over the window (spurious, fitted to noise at the ends) would make
    # the amplitude fit non-finite, on which LAPACK's least squares does not return
    with np.errstate(divide="ignore"):
        mu = mu[(np.abs(mu) > 0) & (np.log(np.abs(mu)) * (N - 1) < 600.0)]
    lam = np.log(mu) / dt
    Z = np.exp(np.outer(t - t[0], lam))
    amp = np.linalg.lstsq(Z, x.astype(complex), rcond=None)[0]
    return PencilModes(lam, amp, s * scale, float(t[0]), dt, N)


def _decimation(t: np.ndarray, x: np.ndarray, max_samples: int) -> tuple[int, int]:
    """Stride and number of samples for the pencil: within ``max_samples``, without aliasing the content."""
    N = t.size
    if N <= max_samples:
        return 1, N
    X = np.abs(np.fft.rfft(x - x.mean(axis=0), axis=0)) ** 2
    p = X.sum(axis=1)
    f = np.fft.rfftfreq(N)  # cycles per sample
    sig = np.flatnonzero(p > 1e-6 * p.max()) if p.max() > 0 else np.array([0])
    fmax = float(f[sig[-1]]) if sig.size else 0.5
    smax = max(int(0.4 / fmax), 1) if fmax > 0 else N  # decimated Nyquist above 1.25 fmax
    stride = max(min(smax, math.ceil(N / max_samples)), 1)
    return stride, min(max_samples, (N - 1) // stride + 1)


def _pick(t: np.ndarray, x: np.ndarray, reference: complex | None) -> tuple[PencilModes, complex]:
    """Pencil fit and its dominant pole (or the one nearest ``reference``), with ``Im >= 0``.

    Poles closer to the chosen one than the resolution ``2 pi / T`` of the
    window cannot be told apart (a pencil may split a slowly modulated
    oscillation into such a pair); the order is then lowered by two until
    the chosen pole stands alone.
    """
    order = None
    res = 2 * math.pi / max(float(t[-1] - t[0]), 1e-300)
    while True:
        pm = matrix_pencil(t, x, order=order)
        lam_all = pm.eigenvalues
        keep = lam_all.imag >= -1e-9 * np.abs(lam_all)
        if not keep.any():
            keep[:] = True
        size = np.where(keep, pm.size_at(float(t[-1])), -1.0)
        k = int(np.argmax(size)) if reference is None else int(np.argmin(np.abs(lam_all - reference)))
        lam = complex(lam_all[k])
        near = np.abs(lam_all - lam) < res
        near[k] = False
        near &= np.abs(lam_all - lam.conjugate()) > 1e-9 * abs(lam) + 1e-12
        if not near.any() or lam_all.size <= 2:
            break
        order = lam_all.size - 2
    return pm, (lam.conjugate() if lam.imag < 0 else lam)


def dominant_mode(
    t: np.ndarray, x: np.ndarray, *, max_samples: int = 1024, reference: complex | None = None,
    coordinates: int | None = None,
) -> ModeEstimate:
    """Growth rate and frequency of the mode with the largest amplitude at the end of the window (matrix pencil).

    Long records are decimated (never below 2.5 samples per period of the
    highest frequency with more than 1e-6 of the spectral power) and, if
    still longer than ``max_samples``, cut to their last ``max_samples``
    decimated samples.  The uncertainty is the larger deviation of the
    estimates on the two halves of the (decimated) window from the full
    estimate.

    Parameters
    ----------
    t : ndarray, shape (N,)
        Uniform sample times [s].
    x : ndarray, shape (N,) or (N, m)
        Samples (e.g. state deviations ``(dq, dqdot)``; the mode's share is
        measured on the first ``m // 2`` columns).
    max_samples : int, optional
        Most samples given to the pencil (default 1024).
    reference : complex, optional
        Report the pole nearest this eigenvalue [1/s] instead of the dominant
        one (e.g. to cross-check a modal projection).
    coordinates : int, optional
        Number of coordinates ``n`` among the columns of ``x`` (default half
        of them), for the mode's share (as in :func:`modal_projection`).

    Returns
    -------
    ModeEstimate
        ``estimator = "matrix-pencil"``; ``share`` is the mode's part of the
        coordinates' motion at the end of the window.

    Raises
    ------
    ParameterError
        If the samples are not uniform or fewer than 16.
    """
    t, x = _check_samples(t, x)
    if t.size < 16:
        raise ParameterError(f"the matrix pencil needs at least 16 samples; got {t.size}")
    stride, n = _decimation(t, x, max_samples)
    idx = np.arange(t.size - 1 - (n - 1) * stride, t.size, stride)
    tt, xx = t[idx], np.asarray(x)[idx]
    pm, lam = _pick(tt, xx, reference)
    g_err = f_err = math.nan
    h = n // 2
    if h >= 16:
        errs = []
        for sl in (slice(0, h), slice(n - h, n)):
            try:
                other = _pick(tt[sl], xx[sl], lam)[1]
            except ParameterError:
                continue
            if other.imag < 0:
                other = other.conjugate()
            errs.append(other - lam)
        if len(errs) == 2:
            g_err = max(abs(e.real) for e in errs)
            f_err = max(abs(e.imag) for e in errs) / (2 * math.pi)
    # the mode's share of the motion (both members of a complex pair)
    Z = np.exp(np.outer(tt - tt[0], pm.eigenvalues))
    sel = np.abs(pm.eigenvalues - lam) < 1e-9 * abs(lam) + 1e-12
    sel |= np.abs(pm.eigenvalues - lam.conjugate()) < 1e-9 * abs(lam) + 1e-12
    part = np.real(Z[:, sel] @ pm.amplitudes[sel])
    share = _share(np.real(xx), part, coordinates)
    fit = np.real(Z @ pm.amplitudes)
    res = float(np.linalg.norm(fit - np.real(xx))) / max(float(np.linalg.norm(np.real(xx))), 1e-300)
    rate = 1.0 / pm.dt
    warns: list[str] = []
    if math.isfinite(share) and share < 0.5 and reference is None:
        warns.append(f"no single mode dominates: the largest carries {100 * share:.3g} % of the motion")
    return ModeEstimate(lam.real, g_err, lam.imag / (2 * math.pi), f_err, "matrix-pencil",
                        (float(tt[0]), float(tt[-1])), n, rate, share, res, None,
                        tuple(warns))  # fmt: skip
