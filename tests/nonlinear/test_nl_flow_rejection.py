"""ScipyFlow and a vector field that cannot be evaluated at some trial states (issue #14, damped pads).

A brake model's vector field raises ``ParameterError`` where its pad equations have no solution; SciPy evaluates
it at the stages of trial steps, which may lie there although the solution never does.  The flow must then reject
the step (a smaller one follows), not abort; where the solution itself reaches such states it must fail with a
``FlowError``, never return a number.  Reference: the closed-form solution ``x(t) = x0 exp(-k t)``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from brakesqueal.errors import ParameterError
from brakesqueal.nonlinear.flow import FlowError, ScipyFlow
from brakesqueal.nonlinear.system import SmoothSystem

K = 50.0


def _system(forbidden: float) -> tuple[SmoothSystem, list[int]]:
    raised = [0]

    def f(x: np.ndarray, p: float) -> np.ndarray:
        if x[0] < forbidden:  # the "pad equations" have no solution here
            raised[0] += 1
            raise ParameterError("cannot be evaluated")
        return np.array([-K * x[0]])

    return SmoothSystem(f=f, jac=lambda x, p: np.array([[-K]]), n=1, dfdp=lambda x, p: np.zeros(1)), raised


@pytest.mark.parametrize("sens", [False, True])
def test_a_trial_stage_out_of_the_domain_is_a_rejected_step(sens: bool) -> None:
    # the exact solution decays towards 0 and never goes below 0; explicit stages of long steps overshoot below it
    system, raised = _system(-1e-9)
    r = ScipyFlow(system, rtol=1e-6)(np.array([1.0]), 1.0, 0.0, sensitivities=sens)
    assert raised[0] > 0  # the out-of-domain stages were met (the test can fail)
    assert abs(float(r.x[0]) - math.exp(-K)) < 1e-6 * 1.0


def test_a_solution_that_enters_the_domain_fails_with_a_flow_error() -> None:
    system, _ = _system(0.5)  # the solution itself crosses x = 0.5 at t = ln 2 / K
    with pytest.raises(FlowError):
        ScipyFlow(system, rtol=1e-6)(np.array([1.0]), 1.0, 0.0, sensitivities=False)
