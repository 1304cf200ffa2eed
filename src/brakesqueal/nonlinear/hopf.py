r"""Hopf points: first Lyapunov coefficient, criticality and the predicted limit cycle.

Conventions (those of MatCont, Kuznetsov's *Elements of Applied Bifurcation
Theory*, 3rd ed., sec. 3.5 and 10.2):

* state ``x`` in the system's own (SI) units, ``A = f_x(x0, p0)`` with a
  simple pair ``lambda = +-i omega0``, ``omega0 > 0``;
* ``<a, b> = conj(a)^T b``; ``A q = i omega0 q``, ``A^T p = -i omega0 p``,
  ``<q, q> = 1``, ``<p, q> = 1`` (the phase of ``q`` is fixed so that its
  largest component is real and positive; ``c1`` does not depend on it);
* the projection formula

  .. math::

     c_1 = \tfrac12 \langle p,\; C(q,q,\bar q) + B(\bar q, h_{20}) + 2 B(q, h_{11})\rangle,
     \quad h_{20} = (2 i\omega_0 I - A)^{-1} B(q,q),\quad h_{11} = -A^{-1} B(q,\bar q),

  is the complex coefficient of the Poincaré normal form
  ``z' = (mu(p) + i omega(p)) z + c1 z |z|^2`` on the centre manifold
  ``x = x0 + z q + conj(z q) + h20 z^2 / 2 + h11 |z|^2 + conj(h20 z^2) / 2 + ...``;
* ``l1 = Re(c1) / omega0`` (MatCont's "first Lyapunov coefficient");
  ``l1 < 0``: supercritical (stable cycles), ``l1 > 0``: subcritical.

Predicted cycle (from the normal form truncated at third order):
``|z|^2 = -mu'(p0) (p - p0) / Re c1`` on the side ``sign(p - p0) =
-sign(Re c1 * mu')``, where ``mu' = dRe(lambda)/dp`` along the equilibrium
branch.  The first-harmonic amplitude of coordinate ``j`` is
``A_j = 2 |q_j| |z| = a_j sqrt(|p - p0|)`` with
``a_j = 2 |q_j| sqrt(|mu' / Re c1|)``, independent of how ``q`` is
normalised.  The angular frequency is ``omega0 + (omega' - mu' Im c1 /
Re c1) (p - p0)``.  The relative errors of both are ``O(|p - p0|)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg as sla

from ..errors import BrakesquealError, ParameterError
from .system import EPS, H_FIRST, H_SECOND, SmoothSystem, step_plateau

__all__ = ["HopfResult", "CycleGuess", "first_lyapunov", "hopf_result"]


@dataclass(frozen=True)
class CycleGuess:
    """An approximate periodic orbit (initial guess for shooting).

    Attributes
    ----------
    x : ndarray, shape (m, n)
        States at the starts of ``m`` equal time segments (``x[0]`` at phase 0).
    period : float
        Period [s].
    p : float
        Parameter value.
    amplitude : ndarray, shape (n,)
        Predicted first-harmonic amplitude per coordinate.
    """

    x: np.ndarray
    period: float
    p: float
    amplitude: np.ndarray


@dataclass(frozen=True)
class HopfResult:
    r"""First Lyapunov coefficient and limit-cycle prediction at a Hopf point.

    Attributes
    ----------
    x0 : ndarray, shape (n,)
        Equilibrium at the Hopf point (refined when ``refine=True``).
    p0 : float
        Parameter at the Hopf point (refined when ``refine=True``).
    eigenvalue : complex
        The critical eigenvalue ``~ i omega0`` (its real part is the residual).
    omega0 : float
        Angular frequency at onset [rad/s].
    q, p : ndarray, shape (n,), complex
        Right and left eigenvectors: ``A q = i omega0 q``, ``A^T p = -i omega0 p``,
        ``<q, q> = 1``, ``<p, q> = 1``.
    c1 : complex
        Normal-form coefficient (Kuznetsov's projection formula, see module docstring).
    l1 : float
        First Lyapunov coefficient ``Re(c1) / omega0`` [1/(s·unit^2) per the
        normalisation ``<q, q> = 1``].
    l1_error : float
        Error estimate of ``l1`` (finite differences, rounding, distance of the
        eigenvalue from the imaginary axis).
    criticality : str
        ``"supercritical"`` (``l1 < -10 l1_error``), ``"subcritical"``
        (``l1 > 10 l1_error``) or ``"degenerate"``.
    dlambda_dp : complex
        Derivative of the critical eigenvalue along the equilibrium branch.
    dRe_lambda_dp : float
        Transversality coefficient ``mu' = Re(dlambda_dp)``.
    dx0_dp : ndarray, shape (n,)
        Derivative of the equilibrium, ``-A^{-1} f_p``.
    h20, h11 : ndarray, shape (n,)
        Second-order centre-manifold coefficients.
    side : int
        ``+1`` or ``-1``: the cycles exist for ``sign(p - p0) = side``
        (``0`` when degenerate or not transversal).
    amplitude_coefficients : ndarray, shape (n,)
        ``a_j``: first-harmonic amplitude ``A_j ~ a_j sqrt(|p - p0|)``.
    frequency_slope : float
        ``d omega / dp`` of the emerging cycles [rad/s per unit of p].
    multilinear : str
        ``"exact"`` or ``"finite-difference"`` (how ``B`` and ``C`` were obtained).
    refined : bool
        Whether ``(x0, p0)`` were refined by Newton iterations.
    state_names : tuple of str
        Coordinate names.
    parameter_name : str
        Name of the parameter.
    eigenvalues : ndarray
        All eigenvalues of ``A`` at the Hopf point.
    warnings : tuple of str
        Non-generic features found (other eigenvalues near the imaginary axis,
        a vanishing transversality).
    """

    x0: np.ndarray
    p0: float
    eigenvalue: complex
    omega0: float
    q: np.ndarray
    p: np.ndarray
    c1: complex
    l1: float
    l1_error: float
    criticality: str
    dlambda_dp: complex
    dRe_lambda_dp: float
    dx0_dp: np.ndarray
    h20: np.ndarray
    h11: np.ndarray
    side: int
    amplitude_coefficients: np.ndarray
    frequency_slope: float
    multilinear: str
    refined: bool
    state_names: tuple[str, ...]
    parameter_name: str
    eigenvalues: np.ndarray = field(repr=False)
    warnings: tuple[str, ...] = ()

    # ---------------------------------------------------------- derived values
    @property
    def period0(self) -> float:
        """Period at onset ``2 pi / omega0`` [s]."""
        return 2 * math.pi / self.omega0

    @property
    def frequency0_hz(self) -> float:
        """Frequency at onset ``omega0 / (2 pi)`` [Hz]."""
        return self.omega0 / (2 * math.pi)

    def _dp(self, p: float) -> float:
        if self.side == 0:
            raise BrakesquealError(
                f"no limit-cycle prediction at this Hopf point: it is {self.criticality}"
                + ("" if self.criticality == "degenerate" else " but not transversal (dRe_lambda_dp ~ 0)")
            )
        dp = float(p) - self.p0
        if not math.isfinite(dp) or dp * self.side <= 0:
            side = ">" if self.side > 0 else "<"
            raise ParameterError(
                f"The parameter {self.parameter_name} = {p!r} is on the side without cycles; "
                f"allowed {self.parameter_name} {side} {self.p0:.12g}"
            )
        return dp

    def radius(self, p: float) -> float:
        """Normal-form radius ``|z| = sqrt(-mu' (p - p0) / Re c1)`` (depends on the normalisation of ``q``).

        Parameters
        ----------
        p : float
            Parameter value on the side where cycles exist.

        Returns
        -------
        float
            ``|z|``.
        """
        dp = self._dp(p)
        return math.sqrt(-self.dRe_lambda_dp * dp / self.c1.real)

    def amplitude(self, p: float) -> np.ndarray:
        """Predicted first-harmonic amplitude of each coordinate, ``a_j sqrt(|p - p0|)``.

        Parameters
        ----------
        p : float
            Parameter value on the side where cycles exist.

        Returns
        -------
        ndarray, shape (n,)
            Amplitudes in the coordinates' units.
        """
        return self.amplitude_coefficients * math.sqrt(abs(self._dp(p)))

    def omega(self, p: float) -> float:
        """Predicted angular frequency of the cycle [rad/s].

        Parameters
        ----------
        p : float
            Parameter value on the side where cycles exist.

        Returns
        -------
        float
            ``omega0 + frequency_slope (p - p0)``.
        """
        return self.omega0 + self.frequency_slope * self._dp(p)

    def period(self, p: float) -> float:
        """Predicted period ``2 pi / omega(p)`` [s].

        Parameters
        ----------
        p : float
            Parameter value on the side where cycles exist.

        Returns
        -------
        float
            The period.
        """
        return 2 * math.pi / self.omega(p)

    def cycle_guess(self, p: float, n_segments: int = 1) -> CycleGuess:
        r"""Approximate cycle at ``p``: the centre-manifold expansion to second order.

        ``x(theta) = x0 + dx0_dp (p - p0) + 2 Re(z q) + Re(h20 z^2) + h11 |z|^2``
        with ``z = |z| exp(i theta)``, sampled at ``theta = 2 pi k / m``.

        Parameters
        ----------
        p : float
            Parameter value on the side where cycles exist.
        n_segments : int
            Number ``m`` of shooting segments.

        Returns
        -------
        CycleGuess
            States, period, parameter, predicted amplitudes.
        """
        if not (isinstance(n_segments, (int, np.integer)) and n_segments >= 1):
            raise ParameterError(f"The option 'n_segments' must be a positive integer; got {n_segments!r}")
        dp = self._dp(p)
        r = self.radius(p)
        theta = 2 * math.pi * np.arange(n_segments) / n_segments
        z = r * np.exp(1j * theta)
        xe = self.x0 + self.dx0_dp * dp
        X = (xe[None, :] + 2 * np.real(z[:, None] * self.q[None, :]) + np.real(z[:, None] ** 2 * self.h20[None, :])
             + (r * r) * self.h11.real[None, :])  # fmt: skip
        return CycleGuess(x=X, period=self.period(p), p=float(p), amplitude=self.amplitude(p))

    def as_dict(self) -> dict[str, Any]:
        """A JSON-friendly summary (complex numbers as ``[re, im]``).

        Returns
        -------
        dict
            Scalars and per-coordinate amplitude coefficients.
        """
        return {
            "parameter": self.parameter_name,
            "p0": self.p0,
            "omega0": self.omega0,
            "frequency0_hz": self.frequency0_hz,
            "c1": [self.c1.real, self.c1.imag],
            "l1": self.l1,
            "l1_error": self.l1_error,
            "criticality": self.criticality,
            "dRe_lambda_dp": self.dRe_lambda_dp,
            "dlambda_dp": [self.dlambda_dp.real, self.dlambda_dp.imag],
            "side": self.side,
            "amplitude_coefficients": dict(zip(self.state_names, map(float, self.amplitude_coefficients))),
            "frequency_slope": self.frequency_slope,
            "multilinear": self.multilinear,
            "refined": self.refined,
            "warnings": list(self.warnings),
        }


# ------------------------------------------------------------------ internals
def _equilibrium(system: SmoothSystem, x: np.ndarray, p: float, max_iter: int = 30) -> np.ndarray:
    """Newton on ``f(x, p) = 0`` from ``x``."""
    x = np.array(x, dtype=float)
    scale = max(float(np.max(np.abs(x))), 1.0)
    for _ in range(max_iter):
        fx = system.rhs(x, p)
        if not np.all(np.isfinite(fx)):
            break
        J = system.jacobian(x, p)
        try:
            dx = np.linalg.solve(J, fx)
        except np.linalg.LinAlgError:
            raise BrakesquealError(f"the Jacobian is singular at {system.parameter_name} = {p:.12g}: "
                                   "no isolated equilibrium (zero eigenvalue)") from None  # fmt: skip
        x -= dx
        if float(np.max(np.abs(dx))) <= 1e-15 * scale:
            return x
    fx = system.rhs(x, p)
    resid = float(np.max(np.abs(fx)))
    if not math.isfinite(resid) or resid > 1e-8 * max(1.0, float(np.max(np.abs(system.jacobian(x, p) @ x)))):
        raise BrakesquealError(f"x0 is not close to an equilibrium at {system.parameter_name} = {p:.12g} "
                               f"(Newton did not converge, |f| = {resid:.3g})")  # fmt: skip
    return x


def _critical_pair(A: np.ndarray, omega: float | None,
                   q_prev: np.ndarray | None = None) -> tuple[np.ndarray, int, np.ndarray, np.ndarray]:  # fmt: skip
    """Eigen-decomposition and the index of the critical eigenvalue (``Im > 0``).

    Selection: the eigenvector closest in direction to ``q_prev`` (tracking during refinement: mode
    coupling puts two pairs at nearly the same frequency), else the imaginary part closest to ``omega``,
    else the pair closest to the imaginary axis.
    """
    lam, vl, vr = sla.eig(A, left=True, right=True)
    normA = max(float(np.linalg.norm(A, 2)), 1e-300)
    cand = np.flatnonzero(lam.imag > 1e-10 * normA)
    if cand.size == 0:
        raise ParameterError("no complex eigenvalue pair at (x0, p0): not a Hopf point "
                             f"(eigenvalues {np.array2string(lam, precision=4)})")  # fmt: skip
    if q_prev is not None:
        score = [abs(np.vdot(q_prev, vr[:, j])) / np.linalg.norm(vr[:, j]) for j in cand]
        k = int(cand[int(np.argmax(score))])
    elif omega is not None:
        k = int(cand[np.argmin(np.abs(lam[cand].imag - omega))])
    else:
        k = int(cand[np.argmin(np.abs(lam[cand].real))])
    return lam, k, vr[:, k], vl[:, k]


def _normalise(q: np.ndarray, pv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    q = q / np.linalg.norm(q)
    j = int(np.argmax(np.abs(q)))
    q = q * (abs(q[j]) / q[j])  # largest component real positive
    pq = np.vdot(pv, q)
    if abs(pq) == 0:
        raise BrakesquealError("<p, q> = 0: the critical eigenvalue is not simple")
    pv = pv / np.conj(pq)
    return q, pv


def _eigen_derivative(system: SmoothSystem, x: np.ndarray, p: float, A: np.ndarray, q: np.ndarray,
                      pv: np.ndarray) -> tuple[complex, np.ndarray]:  # fmt: skip
    """``(d lambda / dp, dx0/dp)`` along the equilibrium branch: ``<p, (A_p + B(., x')) q>``."""
    xp = -np.linalg.solve(A, system.f_p(x, p))
    Bq, _ = system.bilinear(x, p, q, xp.astype(complex))
    dA_q = system.A_p(x, p) @ q + Bq
    return complex(np.vdot(pv, dA_q)), xp


def _c1(system: SmoothSystem, x: np.ndarray, p: float, A: np.ndarray, omega: float, q: np.ndarray,
        pv: np.ndarray, step_factor: float = 1.0) -> tuple[complex, np.ndarray, np.ndarray, float, float]:  # fmt: skip
    """``(c1, h20, h11, sum of |terms|, Skeel condition of the two solves)``."""
    n = x.size
    if step_factor == 1.0:
        stepB = stepC = None  # the system's own (default or fd_step) steps
    else:
        sc = max(1.0, float(np.max(np.abs(x))))
        fd = system.fd_step
        stepB = (fd if fd is not None else H_FIRST * sc) * step_factor
        stepC = (fd * H_SECOND / H_FIRST if fd is not None else H_SECOND * sc) * step_factor
    qb = np.conj(q)
    Bqq, _ = system.bilinear(x, p, q, q, step=stepB)
    Bqqb, _ = system.bilinear(x, p, q, qb, step=stepB)
    h20 = np.linalg.solve(2j * omega * np.eye(n) - A, Bqq)
    h11 = -np.linalg.solve(A, np.real(Bqqb))
    Cqqqb, _ = system.trilinear(x, p, q, q, qb, step=stepC)
    Bqbh20, _ = system.bilinear(x, p, qb, h20, step=stepB)
    Bqh11, _ = system.bilinear(x, p, q, h11.astype(complex), step=stepB)
    t1, t2, t3 = np.vdot(pv, Cqqqb), np.vdot(pv, Bqbh20), 2 * np.vdot(pv, Bqh11)
    c1 = 0.5 * complex(t1 + t2 + t3)
    terms = float(abs(t1) + abs(t2) + abs(t3))
    # rounding of the two solves: Skeel's condition numbers (invariant to row scaling, so badly scaled
    # SI states do not inflate them)
    kap = _skeel(A, h11) + _skeel(2j * omega * np.eye(n) - A, h20)
    return c1, h20, h11, terms, kap


def _skeel(M: np.ndarray, x: np.ndarray) -> float:
    """Skeel's condition number ``|| |M^-1| |M| |x| ||_inf / ||x||_inf`` of the solve giving ``x``."""
    nx = float(np.max(np.abs(x)))
    if nx == 0:
        return 1.0
    return float(np.max(np.abs(np.linalg.inv(M)) @ (np.abs(M) @ np.abs(x)))) / nx


def _eig_condition(A: np.ndarray, w0: float, q: np.ndarray, pv: np.ndarray) -> float:
    """Condition of the critical eigenvector: the bordered system of the balanced matrix (as LAPACK sees it)."""
    Ab, (scale, perm) = sla.matrix_balance(A, permute=False, separate=True)
    qb = q / scale
    pb = np.conj(pv) * scale
    nb = max(float(np.linalg.norm(Ab, 2)), 1e-300)
    K = np.block([[Ab - 1j * w0 * np.eye(A.shape[0]), nb * (qb / np.linalg.norm(qb))[:, None]],
                  [nb * (pb / np.linalg.norm(pb))[None, :], np.zeros((1, 1))]])  # fmt: skip
    return float(np.linalg.cond(K))


def first_lyapunov(system: SmoothSystem, x0: Any, p0: float, *, refine: bool = True, omega: float | None = None,
                   hopf_tol: float = 1e-6) -> HopfResult:  # fmt: skip
    r"""First Lyapunov coefficient, criticality and cycle prediction at a Hopf point.

    Parameters
    ----------
    system : SmoothSystem
        The vector field (exact ``B``/``C`` used when given, else finite
        differences of the Jacobian).
    x0 : array_like, shape (n,)
        Equilibrium at (or near) the Hopf point.
    p0 : float
        Parameter at (or near) the Hopf point.
    refine : bool
        Refine ``(x0, p0)`` first: Newton on ``f(x, p) = 0`` in ``x`` and on
        ``Re lambda(p) = 0`` in ``p`` (with the exact eigenvalue derivative)
        until ``|Re lambda|`` is at rounding level.  With ``False`` the given
        point is used as is and must satisfy ``|Re lambda| <= hopf_tol |lambda|``.
    omega : float, optional
        Select the pair with imaginary part closest to ``omega`` (default: the
        pair closest to the imaginary axis).
    hopf_tol : float
        Tolerance on ``|Re lambda| / |lambda|`` for an unrefined point.

    Returns
    -------
    HopfResult
        ``omega0, q, p, c1, l1, l1_error, criticality, dRe_lambda_dp``, the
        amplitude coefficients and the cycle prediction.

    Raises
    ------
    ParameterError
        No complex pair, or (unrefined) the pair is off the imaginary axis.
    BrakesquealError
        ``x0`` is not near an equilibrium, a zero eigenvalue, or the
        refinement fails.
    """
    if not isinstance(system, SmoothSystem):
        raise ParameterError(f"first_lyapunov: 'system' must be a SmoothSystem; got {type(system).__name__}")
    x = np.asarray(x0, dtype=float).ravel().copy()
    if x.size != system.n or not np.all(np.isfinite(x)):
        raise ParameterError(f"The equilibrium x0 must have {system.n} finite values; got {np.asarray(x0)!r}")
    p = float(p0)
    if not math.isfinite(p):
        raise ParameterError(f"The parameter {system.parameter_name} must be finite; got {p0!r}")
    if not (0 < hopf_tol < 1):
        raise ParameterError(f"The option 'hopf_tol' must be in (0, 1); got {hopf_tol!r}")
    x = _equilibrium(system, x, p)
    A = system.jacobian(x, p)
    lam, k, q, pv = _critical_pair(A, omega)
    q, pv = _normalise(q, pv)
    refined = False
    if refine:
        for _ in range(40):
            dl, _xp = _eigen_derivative(system, x, p, A, q, pv)
            if dl.real == 0:
                raise BrakesquealError("cannot refine the Hopf point: dRe(lambda)/dp = 0 (not transversal)")
            step = -lam[k].real / dl.real
            p_new = p + step
            x = _equilibrium(system, x + _xp * step, p_new)
            p = p_new
            A = system.jacobian(x, p)
            lam, k, q, pv = _critical_pair(A, None, q)
            q, pv = _normalise(q, pv)
            if abs(step) <= 4 * EPS * max(1.0, abs(p)) or abs(lam[k].real) <= 4 * EPS * float(np.linalg.norm(A, 2)):
                refined = True
                break
        else:
            raise BrakesquealError(f"the Hopf point did not converge (last Re lambda = {lam[k].real:.3g} "
                                   f"at {system.parameter_name} = {p:.12g})")  # fmt: skip
    lam_k = complex(lam[k])
    w0 = lam_k.imag
    if not refine and abs(lam_k.real) > hopf_tol * abs(lam_k):
        raise ParameterError(
            f"(x0, p0) is not a Hopf point: Re(lambda)/|lambda| = {lam_k.real / abs(lam_k):.3g} "
            f"exceeds hopf_tol = {hopf_tol:g} (use refine=True)"
        )
    normA = float(np.linalg.norm(A, 2))
    warnings: list[str] = []
    others = np.delete(lam, [k, int(np.argmin(np.abs(lam - np.conj(lam_k))))])
    near = others[np.abs(others.real) <= 1e-8 * max(normA, 1e-300)]
    if near.size:
        warnings.append(f"other eigenvalues on the imaginary axis: {np.array2string(near, precision=6)} "
                        "(codimension-2 point; the centre manifold is larger than 2-D)")  # fmt: skip
    if np.min(np.abs(lam)) <= 1e-12 * normA:
        raise BrakesquealError("A has a zero eigenvalue at the Hopf point (fold-Hopf): l1 is not defined")
    dl, xp = _eigen_derivative(system, x, p, A, q, pv)
    c1, h20, h11, terms, kap = _c1(system, x, p, A, w0, q, pv)
    exact = system.exact_multilinear
    fd_err = 0.0
    if not exact:
        # the same with doubled steps: the difference bounds the truncation error (many times over)
        # and measures the round-off noise of the finite differences
        c1b, *_ = _c1(system, x, p, A, w0, q, pv, step_factor=2.0)
        fd_err = abs(c1 - c1b)
        if fd_err > 1e-6 * abs(c1):
            # badly scaled states (SI units, stiff pads): the default step is off the plateau (truncation above it,
            # rounding below); take the step of a geometric sequence (64x larger to 4^10 smaller) where consecutive
            # results agree best, with the agreement on both sides as the error
            at_default = (c1, h20, h11, terms, kap)
            (c1, h20, h11, terms, kap), before, after = step_plateau(
                lambda f: at_default if f == 1.0 else _c1(system, x, p, A, w0, q, pv, step_factor=f),
                range(-3, 11), skip=(BrakesquealError, np.linalg.LinAlgError))
            fd_err = max(before, after)
    err_round = 10 * EPS * (kap + _eig_condition(A, w0, q, pv)) * terms
    err_off = abs(lam_k.real) / max(abs(lam_k), 1e-300) * terms
    c1_err = fd_err + err_round + err_off
    return hopf_result(x, p, lam, lam_k, q, pv, c1, c1_err, dl, xp, h20, h11,
                       multilinear="exact" if exact else "finite-difference", refined=refined,
                       state_names=tuple(system.state_names or ()), parameter_name=system.parameter_name,
                       warnings=warnings)


def hopf_result(x0: np.ndarray, p0: float, eigenvalues: np.ndarray, eigenvalue: complex, q: np.ndarray,
                pv: np.ndarray, c1: complex, c1_error: float, dlambda_dp: complex, dx0_dp: np.ndarray,
                h20: np.ndarray, h11: np.ndarray, *, multilinear: str, refined: bool, state_names: tuple[str, ...],
                parameter_name: str, warnings: list[str]) -> HopfResult:  # fmt: skip
    """The :class:`HopfResult` of a normal form: criticality, side, amplitude coefficients, frequency slope.

    Shared by :func:`first_lyapunov` and :func:`brakesqueal.nonlinear.implicit.exact_lyapunov`: ``l1 =
    Re c1 / omega0`` is ``"supercritical"`` below ``-10 l1_error``, ``"subcritical"`` above ``10 l1_error``,
    else ``"degenerate"``; the cycles exist for ``sign(p - p0) = -sign(Re c1 mu')`` with first-harmonic
    amplitudes ``a_j sqrt(|p - p0|)``, ``a_j = 2 |q_j| sqrt(|mu' / Re c1|)`` (module docstring).
    """
    w0 = eigenvalue.imag
    l1 = c1.real / w0
    l1_err = c1_error / w0
    if l1 < -10 * l1_err:
        crit = "supercritical"
    elif l1 > 10 * l1_err:
        crit = "subcritical"
    else:
        crit = "degenerate"
    warnings = list(warnings)
    mu1 = dlambda_dp.real
    transversal = abs(mu1) > 1e-10 * max(abs(dlambda_dp), 1e-300) and abs(mu1) > 0
    if not transversal:
        warnings.append("dRe(lambda)/dp ~ 0: the Hopf point is not transversal; no amplitude prediction")
    if crit != "degenerate" and transversal:
        side = int(-np.sign(c1.real) * np.sign(mu1))
        acoef = 2 * np.abs(q) * math.sqrt(abs(mu1 / c1.real))
        fslope = dlambda_dp.imag - mu1 * c1.imag / c1.real
    else:
        side, acoef, fslope = 0, np.zeros(x0.size), dlambda_dp.imag
    return HopfResult(
        x0=x0, p0=p0, eigenvalue=eigenvalue, omega0=w0, q=q, p=pv, c1=c1, l1=l1, l1_error=l1_err,
        criticality=crit, dlambda_dp=dlambda_dp, dRe_lambda_dp=mu1, dx0_dp=dx0_dp, h20=h20, h11=h11, side=side,
        amplitude_coefficients=acoef, frequency_slope=float(fslope), multilinear=multilinear, refined=refined,
        state_names=state_names, parameter_name=parameter_name, eigenvalues=eigenvalues, warnings=tuple(warnings),
    )  # fmt: skip
