"""Damped Newton iteration shared by the silent-motion solvers (2-DOF engine and built models)."""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..errors import SilentMotionError

__all__ = ["damped_newton"]


def damped_newton(
    f: Callable[[np.ndarray], np.ndarray],
    jac: Callable[[np.ndarray], np.ndarray],
    z0: np.ndarray,
    *,
    atol: np.ndarray | float,
    rtol: float = 1e-13,
    max_iter: int = 80,
    ftol: float = 0.0,
    admissible: Callable[[np.ndarray], bool] | None = None,
) -> tuple[np.ndarray, int]:
    """Solve ``f(z) = 0`` by Newton's method with backtracking on ``|f|``.

    Parameters
    ----------
    f, jac : callable
        Residual (already scaled to comparable magnitudes) and its Jacobian.
    z0 : ndarray
        Starting point.
    atol : float or ndarray
        Absolute step tolerance per unknown; converged when every
        ``|step| <= rtol |z| + atol``.
    rtol : float
        Relative step tolerance.
    max_iter : int
        Maximum number of Newton steps.
    ftol : float
        Also converged when ``max |f(z)| <= ftol`` after a step (the residual is at
        rounding level although the step is not yet below ``atol``).
    admissible : callable, optional
        Trial points for which it returns False are rejected (the step is halved).

    Returns
    -------
    z : ndarray
        The solution.
    iterations : int
        Newton steps used.

    Raises
    ------
    SilentMotionError
        Singular Jacobian, non-finite step, stalled line search (with ``|f|`` not
        already at rounding level) or no convergence within ``max_iter``.
    """
    z = np.array(z0, dtype=float)
    fz = f(z)
    for it in range(1, max_iter + 1):
        try:
            step = np.linalg.solve(jac(z), -fz)
        except np.linalg.LinAlgError:
            raise SilentMotionError("the Jacobian of the silent-motion equations is singular") from None
        if not np.all(np.isfinite(step)):
            raise SilentMotionError("Newton's method produced a non-finite step")
        if np.all(np.abs(step) <= rtol * np.abs(z) + atol):
            return z + step, it
        lam, norm0 = 1.0, np.linalg.norm(fz)
        while lam > 1e-8:
            z_new = z + lam * step
            if admissible is None or admissible(z_new):
                f_new = f(z_new)
                if np.all(np.isfinite(f_new)) and np.linalg.norm(f_new) <= (1 - 1e-4 * lam) * norm0:
                    break
            lam /= 2
        else:
            if norm0 <= 1e-15:
                return z, it
            raise SilentMotionError("Newton's method stalled")
        z, fz = z_new, f_new
        if ftol > 0 and np.max(np.abs(fz)) <= ftol:
            return z, it
    raise SilentMotionError("Newton's method did not converge")
