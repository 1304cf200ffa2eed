"""Template: the one Dormand–Prince 8(5,3) step (numba), read as text and shared by every compiled integrator.

SciPy's ``DOP853`` (Hairer, Nørsett & Wanner, *Solving ODEs I*, sec. II.10;
``scipy.integrate._ivp.rk.DOP853``): its coefficients, its combined 5th/3rd-order
error norm, its step-size control and its 7th-order dense output, ported to
numba.  Two drivers include this text: the simulation's
(:mod:`.simulation_dop853`: 7th-order dense output with the table ``_DD``,
events, unilateral contact) and the flow's (:mod:`.flow_dop853`: variational
equations, samples hit by shortened steps).  Each defines ``_stage_rhs(ctx, y, out)``, the vector field at ``y``
with its context ``ctx`` (a tuple: work arrays, parameters, first-class
functions), so the right-hand side is compiled into the step.

The stand-ins above the marker only make this file a valid, linted module.
"""
# ruff: noqa: E501
# mypy: ignore-errors

import math

import numpy as np
from numba import njit


def _stage_rhs(ctx, y, out):  # defined by the driver that includes this template
    raise NotImplementedError


# ---- template body ----

from scipy.integrate._ivp import dop853_coefficients as _dop853_co  # noqa: E402

#: Stages of one step (the 13th evaluation, at the new state, is the next step's first stage: FSAL).
_NS = 12
_DA = np.ascontiguousarray(_dop853_co.A, dtype=np.float64)  # (16, 16): 12 stages, 3 of the dense output
_DB = np.ascontiguousarray(_dop853_co.B, dtype=np.float64)
_DE3 = np.ascontiguousarray(_dop853_co.E3, dtype=np.float64)
_DE5 = np.ascontiguousarray(_dop853_co.E5, dtype=np.float64)
_DD = np.ascontiguousarray(_dop853_co.D, dtype=np.float64)
#: Step-size control (SciPy's): safety factor, smallest and largest factor, exponent 1/(error order + 1).
_SAFETY = 0.9
_MIN_FACTOR = 0.2
_MAX_FACTOR = 10.0
_EXPO = -1.0 / 8.0


@njit(cache=True, inline="always", error_model="numpy")
def dop853_step(ctx, y, h, rtol, atol, K, ynew, ystage):
    """One step of size h from y with K[0] = f(y): stages K[1..11], the 8th-order solution ynew and
    K[12] = f(ynew); returns the error norm (SciPy's ``_estimate_error_norm``), inf if ynew or f(ynew)
    is not finite."""
    n = y.shape[0]
    for s in range(1, _NS):
        for j in range(n):
            acc = 0.0
            for q in range(s):
                acc += K[q, j] * _DA[s, q]
            ystage[j] = y[j] + h * acc
        _stage_rhs(ctx, ystage, K[s])
    for j in range(n):
        acc = 0.0
        for q in range(_NS):
            acc += K[q, j] * _DB[q]
        ynew[j] = y[j] + h * acc
    _stage_rhs(ctx, ynew, K[_NS])
    for j in range(n):
        if not (abs(ynew[j]) < 1e300 and abs(K[_NS, j]) < 1e300):
            return math.inf
    e5 = 0.0
    e3 = 0.0
    for j in range(n):
        sc = atol[j] + max(abs(y[j]), abs(ynew[j])) * rtol
        a = 0.0
        b = 0.0
        for s in range(_NS + 1):
            a += K[s, j] * _DE5[s]
            b += K[s, j] * _DE3[s]
        e5 += (a / sc) ** 2
        e3 += (b / sc) ** 2
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    err = abs(h) * e5 / math.sqrt((e5 + 0.01 * e3) * n)
    return err if err < math.inf else math.inf


@njit(cache=True, error_model="numpy")
def dop853_factor(err, rejected):
    """Factor of the next step size after a step with error norm err: accepted (err < 1; at most 1 right
    after a rejection) or rejected (at least MIN_FACTOR; MIN_FACTOR for a non-finite step)."""
    if err < 1.0:
        factor = _MAX_FACTOR if err == 0.0 else min(_MAX_FACTOR, _SAFETY * err ** _EXPO)
        return min(1.0, factor) if rejected else factor
    if not err < math.inf:
        return _MIN_FACTOR
    return max(_MIN_FACTOR, _SAFETY * err ** _EXPO)
