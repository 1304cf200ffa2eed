"""Nonlinear time simulation of built models (``brakesqueal simulate --model``).

The residual ``R(Q, Qdot, Qddot, L)`` of a built model is linear in the
accelerations: ``Qddot = -M(Q)^{-1} R(Q, Qdot, 0, L)`` with ``M = dR/dQddot``.
Quasi-static pads' deformations ``L`` follow ``G(Q, Qdot, L) = 0`` (Newton,
warm-started).  Integration uses :func:`scipy.integrate.solve_ivp` with the
model's generated (pure Python) code, so it is slower than the compiled 2-DOF
simulator of :mod:`brakesqueal.simulation`; the same summary numbers and the
contact-loss event are provided.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import numpy as np

from ..errors import ParameterError
from .components import ModelSpec

__all__ = ["BuiltTrajectory", "simulate_model"]


@dataclass(frozen=True, eq=False)
class BuiltTrajectory:
    """Trajectory of a built model.

    Attributes
    ----------
    status : str
        ``"finished"``, ``"contact-loss"`` or ``"failed"``.
    message : str
        One line explaining the status.
    t : ndarray, shape (k,)
        Output times [s].
    Q, Qdot : ndarray, shape (k, n)
        Coordinates and rates (``coords`` order).
    normal_forces : ndarray, shape (k, pads)
        Pad normal forces [N].
    coords : tuple of str
        Coordinate names.
    Q0 : ndarray
        Silent motion.
    modes : LinearModes or None
        Linear modes of the silent motion (for the summary).
    integration_error : float
        Bound on the integrator's error of growth rate and angular frequency [1/s].
    """

    status: str
    message: str
    t: np.ndarray
    Q: np.ndarray
    Qdot: np.ndarray
    normal_forces: np.ndarray
    coords: tuple[str, ...]
    Q0: np.ndarray
    modes: Any = None
    integration_error: float = 0.0

    @property
    def summary(self) -> Any:
        """Growth rate and frequency of the leading mode (modal projection), final amplitude.

        See :func:`brakesqueal.simulation.summarize`; the output samples are
        the estimation samples here (at least 20 per period of the fastest
        linear mode by default).
        """
        from ..simulation.trajectory import summarize

        x = np.concatenate([self.Q - self.Q0, self.Qdot], axis=1)
        return summarize(self.status, self.t, x, self.modes, x_start=x[0] if x.size else None,
                         integration_error=self.integration_error)  # fmt: skip

    def to_xarray(self) -> Any:
        """Dataset with dimension ``t``: one variable per coordinate and rate, and the normal forces."""
        import xarray as xr

        data = {c: ("t", self.Q[:, i]) for i, c in enumerate(self.coords)}
        data.update({f"d{c}": ("t", self.Qdot[:, i]) for i, c in enumerate(self.coords)})
        data["F_n"] = (("t", "pad"), self.normal_forces)
        return xr.Dataset(data, coords={"t": self.t}, attrs={"status": self.status, "message": self.message})

    def to_netcdf(self, path: str) -> None:
        """Write :meth:`to_xarray` to NetCDF."""
        self.to_xarray().to_netcdf(path, engine="scipy")

    def plot(self) -> Any:
        """Time histories of the coordinates' deviations; returns the figure."""
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(len(self.coords), 1, sharex=True, figsize=(8, 1.6 * len(self.coords) + 1))
        for ax, i in zip(np.atleast_1d(axes), range(len(self.coords))):
            ax.plot(self.t, self.Q[:, i] - self.Q0[i], lw=0.6)
            ax.set_ylabel(self.coords[i])
        np.atleast_1d(axes)[-1].set_xlabel("t [s]")
        fig.suptitle(f"{self.status}: {self.message}", fontsize=9)
        return fig


def simulate_model(
    spec: ModelSpec,
    overrides: Mapping[str, Any] | None,
    t_end: float,
    perturbation: Sequence[float] = (1e-5,),
    *,
    method: str = "DOP853",
    rtol: float = 1e-8,
    sample_rate: float | None = None,
) -> BuiltTrajectory:
    """Integrate a built model from its silent motion plus ``perturbation`` (added to the first coordinates).

    ``sample_rate`` [Hz] defaults to the larger of 20 kHz and 20 samples per
    period of the fastest linear mode (:func:`brakesqueal.simulation._integrate.estimation_rate`).

    Raises
    ------
    ParameterError
        Bad ``t_end``, tolerance or perturbation.
    """
    from scipy.integrate import solve_ivp

    if not (math.isfinite(t_end) and t_end > 0):
        raise ParameterError(f"The option '--t-end' must be a positive number of seconds; got {t_end!r}")
    if not 1e-13 <= rtol <= 1e-2:
        raise ParameterError(f"The option '--rtol' must be in [1e-13, 1e-2]; got {rtol!r}")
    from ..simulation._integrate import estimation_rate
    from ..simulation.estimate import linear_modes
    from ..simulation.trajectory import _STAGES, integration_error_bound

    from ..analysis.linear import linearize
    from ..codegen import compile_model

    params = spec.get_preset(None).resolve(dict(overrides or {}))
    lm = linearize(params, pad_rates="quasi-static")  # as integrated below (tangential rates neglected)
    Q0 = lm.silent.q0
    modes = linear_modes(lm.A)
    if sample_rate is None:
        sample_rate = max(20000.0, estimation_rate(modes, t_end))
    cm = compile_model(spec)
    n, m = cm.n, cm.m
    nx = cm.nx
    pert = np.zeros(2 * n)
    if len(perturbation) > 2 * n or not all(math.isfinite(v) for v in perturbation):
        raise ParameterError(f"the perturbation must be at most {2 * n} finite numbers; got {list(perturbation)}")
    pert[: len(perturbation)] = perturbation
    p = [float(v) for v in params.vector()]
    L = lm.silent.l0.copy()
    zeros = [0.0] * n
    rates = [0.0] * m  # the pads' tangential rates are neglected here (quasi-static pads)

    def solve_L(Q: np.ndarray, dQ: np.ndarray) -> np.ndarray:
        nonlocal L
        for _ in range(20):
            x = list(Q) + list(dQ) + zeros + list(L) + rates
            g = np.asarray(cm.residuals(x, p)[n:])
            GL = np.asarray(cm.jacobians(x, p)).reshape(n + m, nx)[n:, 3 * n:3 * n + m]
            step = np.linalg.solve(GL, -g)
            L = L + step
            if np.all(np.abs(step) <= 1e-14 * (np.abs(L) + 1e-12)):
                break
        return L

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        Q, dQ = y[:n], y[n:]
        Lv = solve_L(Q, dQ) if m else L
        x = list(Q) + list(dQ) + zeros + list(Lv) + rates
        R0 = np.asarray(cm.residuals(x, p)[:n])
        M = np.asarray(cm.jacobians(x, p)).reshape(n + m, nx)[:n, 2 * n:3 * n]
        return np.concatenate([dQ, -np.linalg.solve(M, R0)])

    def contact(y: np.ndarray) -> np.ndarray:
        Q, dQ = y[:n], y[n:]
        Lv = solve_L(Q, dQ) if m else L
        return cm.contact_table(list(Q) + list(dQ) + zeros + list(Lv) + rates, p)[:, 0]

    def lift(t: float, y: np.ndarray) -> float:
        return float(contact(y).min())

    lift.terminal = True  # type: ignore[attr-defined]
    lift.direction = -1  # type: ignore[attr-defined]
    y0 = np.concatenate([Q0, np.zeros(n)]) + pert
    if lift(0.0, y0) <= 0:
        raise ParameterError("the initial state has a pad out of contact (normal force <= 0)")
    t_eval = np.arange(0.0, t_end, 1.0 / sample_rate)
    atol = 1e-12 * (1 + np.abs(y0).max())
    sol = solve_ivp(rhs, (0.0, t_end), y0, method=method, rtol=rtol, atol=atol, t_eval=t_eval,
                    events=lift)  # fmt: skip
    Y = sol.y.T
    fn = np.array([contact(y) for y in Y]) if Y.size else np.zeros((0, len(spec.pads)))
    if sol.status == 1:
        status, msg = "contact-loss", f"a pad lost contact at t = {sol.t_events[0][0]:.6g} s"
    elif sol.status == 0:
        status, msg = "finished", "reached the end time"
    else:
        status, msg = "failed", f"solver failed: {sol.message}"
    ie = 0.0
    if Y.shape[0] > 1:
        y_s = np.concatenate([Q0, np.zeros(n)])
        ie = integration_error_bound(Y - y_s, Y, rtol, atol, sol.nfev / _STAGES.get(method, 1), float(sol.t[-1]))
    return BuiltTrajectory(status, msg, sol.t, Y[:, :n], Y[:, n:], fn, cm.coords, Q0, modes, ie)
