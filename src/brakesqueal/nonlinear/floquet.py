r"""Verified Floquet stability: verdicts with an accuracy bound, Hill's method on a shot orbit, cross-checks.

A periodic orbit of an autonomous system always has the multiplier 1 (the phase direction, ``M f = f``); as
computed, its distance from 1 (``trivial_multiplier_error``) measures how accurate the monodromy matrix is.
A stability verdict is only given where the largest non-trivial ``|mu|`` is farther from 1 than a bound
built from that error and the integration tolerance (:func:`multiplier_accuracy`):

* ``"stable"``: every non-trivial ``|mu| < 1 - accuracy``;
* ``"unstable"``: some non-trivial ``|mu| > 1 + accuracy``;
* ``"undecided"``: otherwise (a multiplier within the accuracy of the unit circle: a fold, a Hopf point,
  a period doubling, or an inaccurate monodromy).

Hill's method (:func:`hill_exponents`) computes the Floquet exponents of a smooth system's orbit from the
Fourier series of its Jacobian along the orbit (the infinite Hill matrix truncated to ``H`` harmonics); of the
family ``lambda + i k omega`` of every exponent the copy whose eigenvector is most centred in the harmonic
index is kept.  :func:`cross_check` combines two verdicts of the same orbit (Hill's method and the monodromy):
they must agree, else the orbit is ``"undecided"``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ParameterError

__all__ = ["VERDICTS", "multiplier_accuracy", "stability_verdict", "cross_check", "HillResult", "hill_exponents",
           "exponent_verdict"]

#: The three stability verdicts of a cycle point.
VERDICTS: tuple[str, ...] = ("stable", "unstable", "undecided")


def multiplier_accuracy(trivial_error: float, rtol: float | None = None, *, method: str = "variational",
                        segments: int = 1) -> float:
    """How far from the unit circle a non-trivial multiplier must lie for its side to count.

    ``max(10 |mu_trivial - 1|, 10 m rtol)`` for a variational monodromy over ``m`` shooting segments
    (``sqrt(rtol)`` in place of ``10 m rtol`` for a finite-difference monodromy), where ``rtol`` is the
    integration tolerance: the trivial multiplier is exactly 1, so its computed error is an empirical measure of
    the monodromy's error, and the tolerance a floor below which the eigenvalues are not resolved.

    Parameters
    ----------
    trivial_error : float
        ``|mu_trivial - 1|`` (``nan`` or ``inf``: no bound, every verdict undecided).
    rtol : float, optional
        Relative tolerance of the integration (default ``1e-11``).
    method : {"variational", "finite-difference"}
        How the monodromy was computed.
    segments : int
        Number of shooting segments whose monodromies were multiplied.

    Returns
    -------
    float
    """
    if not math.isfinite(trivial_error):
        return math.inf
    rt = 1e-11 if rtol is None or not math.isfinite(float(rtol)) else float(rtol)
    floor = math.sqrt(rt) if method == "finite-difference" else 10.0 * max(int(segments), 1) * rt
    return max(10.0 * abs(float(trivial_error)), floor)


def stability_verdict(floquet: Any, accuracy: float) -> str:
    """``"stable"``, ``"unstable"`` or ``"undecided"`` from the non-trivial multipliers and their accuracy.

    Parameters
    ----------
    floquet : array_like of complex
        Non-trivial Floquet multipliers.
    accuracy : float
        :func:`multiplier_accuracy`.

    Returns
    -------
    str
        ``"unstable"`` if some ``|mu| > 1 + accuracy``; ``"stable"`` if every ``|mu| < 1 - accuracy``;
        else ``"undecided"``.
    """
    mu = np.abs(np.asarray(floquet, dtype=complex).ravel())
    if not math.isfinite(accuracy) or not np.all(np.isfinite(mu)):
        return "undecided"
    if mu.size == 0:
        return "stable" if accuracy < 1 else "undecided"
    if np.any(mu > 1.0 + accuracy):
        return "unstable"
    if np.all(mu < 1.0 - accuracy):
        return "stable"
    return "undecided"


def exponent_verdict(exponents: Any, accuracy: float) -> str:
    """The verdict of Floquet exponents: ``"unstable"`` if some ``Re > accuracy``, ``"stable"`` if every
    ``Re < -accuracy``, else ``"undecided"``.

    Parameters
    ----------
    exponents : array_like of complex
        Non-trivial Floquet exponents.
    accuracy : float
        Bound on their real parts' error [1/s].

    Returns
    -------
    str
    """
    re = np.real(np.asarray(exponents, dtype=complex).ravel())
    if not math.isfinite(accuracy) or not np.all(np.isfinite(re)):
        return "undecided"
    if np.any(re > accuracy):
        return "unstable"
    if np.all(re < -accuracy):
        return "stable"
    return "undecided"


def cross_check(*verdicts: str | None) -> str:
    """One verdict from several of the same orbit (``None``: a method that does not apply, ignored).

    They must agree; a disagreement, or no verdict at all, is ``"undecided"``.

    Parameters
    ----------
    *verdicts : str or None
        Verdicts from :data:`VERDICTS`.

    Returns
    -------
    str
    """
    got = [v for v in verdicts if v is not None]
    for v in got:
        if v not in VERDICTS:
            raise ParameterError(f"A verdict must be one of {', '.join(VERDICTS)}; got {v!r}")
    if not got or len(set(got)) > 1:
        return "undecided"
    return got[0]


@dataclass(frozen=True)
class HillResult:
    """Floquet exponents of an orbit by Hill's method.

    Attributes
    ----------
    exponents : ndarray, shape (n - 1,), complex
        Non-trivial exponents in the strip ``|Im| <= omega / 2``, by decreasing real part.
    trivial : complex
        The exponent of the phase direction (ideally 0).
    multipliers : ndarray, shape (n - 1,), complex
        ``exp(exponents T)``, by decreasing modulus.
    trivial_multiplier_error : float
        ``|exp(trivial T) - 1|``.
    accuracy : float
        Bound on the exponents' real parts: ``max(10 |trivial|, 1e-9 omega)``.
    verdict : str
        :func:`exponent_verdict` with ``accuracy``.
    harmonics : int
        Number of harmonics ``H`` of the Hill matrix.
    selected : int
        Exponents found (``n`` when every state has one; fewer: ``"undecided"``).
    period : float
        The orbit's period ``T`` [s].
    """

    exponents: np.ndarray
    trivial: complex
    multipliers: np.ndarray
    trivial_multiplier_error: float
    accuracy: float
    verdict: str
    harmonics: int
    selected: int = 0
    period: float = field(default=float("nan"))


def hill_exponents(system: Any, orbit: Any, harmonics: int = 16, *, n_samples: int | None = None,
                   flow: Any = None) -> HillResult:
    """Floquet exponents of a smooth system's periodic orbit by Hill's method.

    The Jacobian ``A(t) = f_x(x(t), p)`` is sampled at ``4H + 4`` (or ``n_samples``) equally spaced phases of
    the orbit (integrated from ``orbit.x[0]``), its Fourier coefficients ``A_j`` form the Hill matrix
    ``(A_{k-l} - i k omega delta_kl)`` over ``k, l = -H..H``, and of its eigenvalues one per state is kept: the
    copy whose eigenvector is most centred in ``k`` (copies ``lambda + i k omega`` of an accepted one are
    skipped), reduced to the strip ``|Im| <= omega / 2``.  The one nearest 0 is the trivial exponent.

    Parameters
    ----------
    system : SmoothSystem
        The system (its Jacobian).
    orbit : PeriodicOrbit
        The orbit (``x[0]``, ``period``, ``p``).
    harmonics : int
        Number of harmonics ``H`` (>= 1).
    n_samples : int, optional
        Phases sampled (default ``4H + 4``; at least ``2H + 1``).
    flow : Flow, optional
        Integrator for the samples (default :class:`~.flow.ScipyFlow` at ``rtol = 1e-11``).

    Returns
    -------
    HillResult

    Raises
    ------
    ParameterError
        Bad ``harmonics`` or ``n_samples``, or a non-smooth system.
    """
    from .flow import ScipyFlow
    from .system import SmoothSystem

    if not isinstance(system, SmoothSystem):
        raise ParameterError(f"hill_exponents: 'system' must be a SmoothSystem; got {type(system).__name__}")
    if not isinstance(harmonics, (int, np.integer)) or isinstance(harmonics, bool) or harmonics < 1:
        raise ParameterError(f"The option 'harmonics' must be an integer >= 1; got {harmonics!r}")
    H = int(harmonics)
    Ms = 4 * H + 4 if n_samples is None else n_samples
    if not isinstance(Ms, (int, np.integer)) or Ms < 2 * H + 1:
        raise ParameterError(f"The option 'n_samples' must be an integer >= 2 harmonics + 1 = {2 * H + 1}; "
                             f"got {n_samples!r}")
    n = system.n
    T, p = float(orbit.period), float(orbit.p)
    omega = 2 * math.pi / T
    fl = flow if flow is not None else ScipyFlow(system)
    x0 = np.asarray(orbit.x, dtype=float).reshape(-1, n)[0]
    fr = fl(x0, T, p, sensitivities=False, n_samples=Ms)
    S = np.asarray(fr.x_samples, dtype=float)[:Ms]  # phases 2 pi j / Ms, j = 0..Ms-1
    A = np.array([system.jacobian(x, p) for x in S])  # (Ms, n, n)
    Ahat = np.fft.fft(A, axis=0) / Ms  # A_j at index j mod Ms
    K = 2 * H + 1
    ks = np.arange(-H, H + 1)
    Hm = np.zeros((n * K, n * K), dtype=complex)
    for a, k in enumerate(ks):
        for b, l in enumerate(ks):
            blk = Ahat[(k - l) % Ms].copy()
            if k == l:
                blk = blk - 1j * k * omega * np.eye(n)
            Hm[a * n:(a + 1) * n, b * n:(b + 1) * n] = blk
    lam, V = np.linalg.eig(Hm)
    Vr = V.reshape(K, n, -1)
    w = (np.abs(Vr) ** 2).sum(axis=1)
    w /= w.sum(axis=0, keepdims=True)
    centre = np.abs((ks[:, None] * w).sum(axis=0))
    strip = lam - 1j * omega * np.round(lam.imag / omega)
    acc: list[int] = []
    for j in np.argsort(centre):
        dup = False
        for i in acc:
            s = int(round((lam[j] - lam[i]).imag / omega))
            if s != 0 and abs(strip[j] - strip[i]) <= 1e-6 * omega:
                dup = True  # lambda_i + i s omega: a copy of an accepted exponent
                break
        if not dup:
            acc.append(int(j))
        if len(acc) == n:
            break
    chosen = strip[acc]
    j0 = int(np.argmin(np.abs(chosen)))
    trivial = complex(chosen[j0])
    rest = np.delete(chosen, j0)
    rest = rest[np.argsort(-rest.real, kind="stable")]
    accuracy = max(10.0 * abs(trivial), 1e-9 * omega)
    verdict = exponent_verdict(rest, accuracy) if len(acc) == n else "undecided"
    mult = np.exp(rest * T)
    mult = mult[np.argsort(-np.abs(mult), kind="stable")]
    return HillResult(rest, trivial, mult, float(abs(np.exp(trivial * T) - 1.0)), accuracy, verdict, H, len(acc),
                      T)
