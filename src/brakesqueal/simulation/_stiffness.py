r"""Feasibility of a requested span for the explicit integrators: a stiff model is refused up front (issue 30).

An explicit Runge–Kutta method is stable only while ``|h lambda|`` stays in
its stability region, whatever the tolerances: DOP853's region reaches at
most :data:`STABILITY_RADIUS` = 6.8 from the origin (RK45's and RK23's are
smaller).  A run over ``[t0, t1]`` therefore needs at least
``(t1 - t0) max|lambda| / 6.8`` steps, ``lambda`` the eigenvalues of the
linearization at the silent motion (the model's fastest time scale; a pad
damper ``d/k``, a pad mass ``sqrt(m/k)``, a disk damper ``Theta/d_t`` ...
all appear there).  With ``d_t = 1e50`` that is about 1e50 steps: the run
went on for ever, its progress line showing an ETA of 1e22-1e42 s.

:func:`check_stiffness` (called by :func:`~._integrate.simulate`, the one entry
of the library and the command line) refuses such a run before it starts
when the estimate exceeds ``max(STIFF_STEP_LIMIT, max_steps)``, with the
estimate, the time it would take at the measured cost of a step, and the
parameters the fastest time scale depends on.  Implicit methods (``Radau``,
``BDF``, ``LSODA``) are not limited by stability and are not checked (the
refusal suggests Radau, which integrates such runs in a few steps).
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Callable

import numpy as np

from ..errors import ParameterError

if TYPE_CHECKING:
    from ..model.parameters import Parameters
    from ._model import SimulationModel
    from .estimate import LinearModes

__all__ = ["STABILITY_RADIUS", "STIFF_STEP_LIMIT", "EXPLICIT_METHODS", "fastest_rate", "check_stiffness"]

#: Largest ``|h lambda|`` inside DOP853's stability region (6.79; RK45 about 3.3, RK23 about 2.5).
STABILITY_RADIUS = 6.8
#: A run of an explicit method that needs more steps than this (or than ``max_steps``, if larger) is refused.
STIFF_STEP_LIMIT = 1e8
#: Methods limited by stability, with their right-hand-side evaluations per step.
EXPLICIT_METHODS: dict[str, int] = {"DOP853-jit": 12, "DOP853": 12, "RK45": 6, "RK23": 3}
#: At most this many parameters are varied to name the ones the fastest time scale depends on.
_MAX_VARIED = 64


def _rate_of(A: np.ndarray) -> float:
    """``max |lambda|`` of a state matrix (NaN if it cannot be computed)."""
    A = np.asarray(A, dtype=float)
    if A.size == 0:
        return 0.0
    if not np.all(np.isfinite(A)):
        return math.nan
    try:
        return float(np.abs(np.linalg.eigvals(A)).max())
    except np.linalg.LinAlgError:
        return math.nan


def fastest_rate(model: SimulationModel, params: Parameters, modes: LinearModes | None = None) -> float:
    """``max |lambda|`` [1/s] of the linearization at the silent motion: ``1 /`` the model's fastest time scale.

    Parameters
    ----------
    model : SimulationModel
        The model.
    params : Parameters
        Its parameter values.
    modes : LinearModes, optional
        The linear modes, when already computed (their eigenvalues are used).

    Returns
    -------
    float
        The rate, or NaN when the linearization is not available (e.g. no silent motion).
    """
    from ..errors import BrakesquealError

    if modes is not None:
        ev = np.abs(np.asarray(modes.eigenvalues))
        if ev.size and np.all(np.isfinite(ev)):
            return float(ev.max())
    try:  # modes are unavailable for a defective leading eigenvalue (e.g. d_t = 1e50): the eigenvalues are not
        return _rate_of(model.linear_matrix(params)[0])
    except (BrakesquealError, np.linalg.LinAlgError, ArithmeticError, ValueError):
        return math.nan


def _dependence(model: SimulationModel, params: Parameters, rate: float) -> list[tuple[str, float]]:
    """Parameters the rate depends on: ``(name, exponent)`` of ``|lambda| ~ name^exponent`` (|exponent| >= 0.25).

    Every finite nonzero parameter is doubled in turn (at most :data:`_MAX_VARIED`); only on the refusal path.
    """
    out: list[tuple[str, float]] = []
    for name in list(params.names)[:_MAX_VARIED]:
        v = float(params[name])
        if not (math.isfinite(v) and v != 0.0):
            continue
        try:
            r2 = _rate_of(model.linear_matrix(params.replace(**{name: 2.0 * v}))[0])
        except Exception:  # noqa: BLE001 - a doubled value may leave the model's range: that name is skipped
            continue
        if math.isfinite(r2) and r2 > 0:
            e = math.log2(r2 / rate)
            if abs(e) >= 0.25:
                out.append((name, e))
    # the strongest dependence first; among equal ones the most extreme value (the one the user likely set)
    out.sort(key=lambda ne: (-round(abs(ne[1]), 1), -abs(math.log10(abs(float(params[ne[0]]))))))
    return out[:3]


def _seconds(s: float) -> str:
    if s < 120:
        return f"{s:.2g} s"
    if s < 2 * 3600:
        return f"{s / 60:.2g} min"
    if s < 2 * 86400:
        return f"{s / 3600:.2g} h"
    if s < 2 * 3.15e7:
        return f"{s / 86400:.2g} days"
    return f"{s / 3.15e7:.2g} years"


def check_stiffness(model: SimulationModel, params: Parameters, t0: float, t1: float, method: str, max_steps: int,
                    modes: LinearModes | None = None, rhs_call: Callable[[], object] | None = None) -> float:
    """Refuse a run of an explicit method whose span needs too many steps for the model's stiffness.

    Parameters
    ----------
    model : SimulationModel
        The model.
    params : Parameters
        Its parameter values.
    t0, t1 : float
        The requested span [s].
    method : str
        The integration method (implicit methods are not checked).
    max_steps : int
        The run's step budget: the limit is ``max(STIFF_STEP_LIMIT, max_steps)``.
    modes : LinearModes, optional
        The linear modes, when already computed.
    rhs_call : callable, optional
        One evaluation of the right-hand side (timed for the message's estimate of the wall time).

    Returns
    -------
    float
        The lower bound of the number of steps (0 for an implicit method, NaN when unknown).

    Raises
    ------
    ParameterError
        The span needs more steps than the limit: one line with the estimate,
        the fastest time scale and the parameters it depends on.
    """
    evals = EXPLICIT_METHODS.get(method)
    if evals is None:
        return 0.0
    rate = fastest_rate(model, params, modes)
    if not (math.isfinite(rate) and rate > 0):
        return math.nan
    span = t1 - t0
    steps = span * rate / STABILITY_RADIUS
    limit = max(STIFF_STEP_LIMIT, float(max_steps) if isinstance(max_steps, (int, float)) else 0.0)
    if not steps > limit:
        return steps
    wall = ""
    if rhs_call is not None:
        best = math.inf
        for _ in range(5):
            w = time.perf_counter()
            rhs_call()
            best = min(best, time.perf_counter() - w)
        per_step = max(evals * best, 1e-7)
        wall = f", about {_seconds(steps * per_step)} at {per_step:.2g} s per step"
    deps = _dependence(model, params, rate)
    by = ""
    if deps:
        by = ", from " + ", ".join(f"{n}={float(params[n]):.4g} (|lambda| ~ {n}^{e:.2g})" for n, e in deps)
    feasible = limit * STABILITY_RADIUS / rate
    raise ParameterError(
        f"the requested span of {span:.4g} s needs at least {steps:.2g} steps of the explicit integrator {method}"
        f"{wall}: the model's fastest time scale is {1 / rate:.2g} s (|lambda| = {rate:.3g} 1/s{by}) and an explicit "
        f"step cannot be longer than {STABILITY_RADIUS:g} of them; at most {limit:.3g} steps are allowed: make the "
        f"model less stiff, shorten the option 't_end' (to at most about {feasible:.2g} s) or use the implicit method "
        "Radau (the option 'method')", parameter="t_end", names=("method", *(n for n, _ in deps)))
