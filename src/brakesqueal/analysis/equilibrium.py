r"""The silent motion ``q_m(t) = q_m0 = const`` (paper eq. 46).

With ``q_mdot = q_mddot = 0`` and ``ldot = 0`` the residuals ``psi`` (eq. 44)
and ``g`` (eqs. 33-34) are four equations in ``(q1, q2, l1, l2)``.  When
``mu1*h10 = mu2*h20`` (eq. 49) the solution is the trivial one, zero; otherwise
it is found by Newton's method with the exact compiled Jacobian, started at
zero (the silent motion is the branch connected to the trivial one).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import SilentMotionError
from ..numeric.compiled import CompiledModel, compiled_model
from ..numeric.newton import damped_newton
from ..parameters import Parameters

__all__ = ["SilentMotion", "silent_motion", "parameter_vector"]

_EQ_IDX = (0, 1, 6, 7)  # q1, q2, l1, l2 in the state vector


def parameter_vector(params: Parameters) -> list[float]:
    """Parameters in the order of the compiled functions (compliances for ``k_ip``)."""
    d = params.as_dict()
    c1, c2 = params.compliances()
    return [
        d["Theta"], d["Phi"], d["k_t"], d["d_t"], d["k1"], d["k2"], d["d1"], d["d2"], c1, c2,
        d["mu1"], d["mu2"], d["h10"], d["h20"], d["r"], d["N0"], d["Omega"],
    ]  # fmt: skip


@dataclass(frozen=True)
class SilentMotion:
    """A silent motion of the 2-DOF model.

    Attributes
    ----------
    q_m0 : ndarray, shape (2,)
        Tilt angles ``(q1, q2)`` [rad] (eq. 46).
    l0 : ndarray, shape (2,)
        Tangential pad deformations [m].
    normal_forces : ndarray, shape (2,)
        ``F_n1, F_n2`` [N] (eqs. 29-30); positive while the pads touch.
    sliding_speeds : ndarray, shape (2,)
        ``|v_r1|, |v_r2|`` [m/s].
    trivial : bool
        True when eq. (49) holds and ``q_m0 = 0`` exactly.
    iterations : int
        Newton iterations used (0 for the trivial solution).
    """

    q_m0: np.ndarray
    l0: np.ndarray
    normal_forces: np.ndarray
    sliding_speeds: np.ndarray
    trivial: bool
    iterations: int

    def state(self) -> list[float]:
        """Full state vector ``x`` of the silent motion (rates zero)."""
        return [self.q_m0[0], self.q_m0[1], 0.0, 0.0, 0.0, 0.0, self.l0[0], self.l0[1], 0.0, 0.0]


def _state(z: np.ndarray) -> list[float]:
    return [z[0], z[1], 0.0, 0.0, 0.0, 0.0, z[2], z[3], 0.0, 0.0]


def _newton(model: CompiledModel, p: list[float]) -> tuple[np.ndarray, int]:
    """Damped Newton on the scaled residuals, from ``z = 0``; returns ``(z, iterations)``."""
    moment_scale = max(p[2], p[15] * (abs(p[12]) + abs(p[13])))  # N m / rad
    scale = np.array([moment_scale, moment_scale, 1.0, 1.0])  # psi in N m, g in m

    def f(z: np.ndarray) -> np.ndarray:
        return np.asarray(model.residuals(_state(z), p)) / scale

    def jac(z: np.ndarray) -> np.ndarray:
        return np.asarray(model.jacobians(_state(z), p)).reshape(4, 10)[:, _EQ_IDX] / scale[:, None]

    return damped_newton(
        f, jac, np.zeros(4), atol=np.array([1e-18, 1e-18, 1e-21, 1e-21]), max_iter=60,
        admissible=lambda z: abs(z[0]) < 1.2 and abs(z[1]) < 1.2,
    )  # fmt: skip


def silent_motion(params: Parameters, *, model: CompiledModel | None = None) -> SilentMotion:
    """Find the silent motion of eq. (46) and check that both pads touch.

    Parameters
    ----------
    params : Parameters
        Model parameters.
    model : CompiledModel, optional
        Compiled model (default: :func:`~brakesqueal.numeric.compiled_model`).

    Returns
    -------
    SilentMotion

    Raises
    ------
    SilentMotionError
        If no silent motion is found, or a pad's normal force is not positive
        there (contact loss), with a message naming the parameters involved.

    Notes
    -----
    Assumes, as the paper does, that both pads slide (``|v_r| > 0``) and stay
    in contact (``F_n > 0``); both are checked.
    """
    model = model or compiled_model()
    p = parameter_vector(params)
    trivial = params.trivial_silent_motion()
    d = params.as_dict()
    moment = d["N0"] * (d["mu1"] * d["h10"] - d["mu2"] * d["h20"])
    if trivial:
        z, its = np.zeros(4), 0
    else:
        try:
            z, its = _newton(model, p)
        except SilentMotionError as exc:
            raise SilentMotionError(
                f"no silent motion found ({exc}) for mu1={d['mu1']:g}, mu2={d['mu2']:g}, h10={d['h10']:g}, "
                f"h20={d['h20']:g}, N0={d['N0']:g}, k_t={d['k_t']:g}: the friction moment "
                f"N0*(mu1*h10 - mu2*h20) = {moment:.6g} N m (eq. 49) is too large for the supports"
            ) from None
    c = model.contact(_state(z), p)
    fn = np.array([c[0], c[3]])
    speeds = np.array([c[1], c[4]])
    if not np.all(np.isfinite(fn)) or np.any(fn <= 0.0):
        bad = 1 if not (fn[0] > 0) else 2
        raise SilentMotionError(
            f"pad {bad} loses contact at the silent motion (normal force F_n{bad} = {fn[bad - 1]:.6g} N <= 0) "
            f"for N0={d['N0']:g}, k{bad}={d[f'k{bad}']:g}, mu1={d['mu1']:g}, mu2={d['mu2']:g}, "
            f"h10={d['h10']:g}, h20={d['h20']:g}"
        )
    if np.any(speeds <= 0.0):
        raise SilentMotionError(f"a pad does not slide at the silent motion (|v_r| = {speeds.min():g} m/s)")
    return SilentMotion(
        q_m0=z[:2].copy(), l0=z[2:].copy(), normal_forces=fn, sliding_speeds=speeds, trivial=trivial, iterations=its
    )
