"""CompiledFlow (numba DOP853 with variational equations) against ScipyFlow and against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

numba = pytest.importorskip("numba")

from brakesqueal.errors import ParameterError  # noqa: E402
from brakesqueal.nonlinear import (CompiledFlow, ScipyFlow, compiled_system, continue_cycles, find_periodic_orbit,  # noqa: E402
                                   first_lyapunov)  # fmt: skip
from brakesqueal.nonlinear.compiled import F_SIGNATURE, JAC_SIGNATURE  # noqa: E402


@numba.njit(F_SIGNATURE)
def bautin_f(x, mu, th, out):
    r2 = x[0] ** 2 + x[1] ** 2
    g = mu + th[0] * r2 - r2**2
    out[0] = g * x[0] - x[1]
    out[1] = g * x[1] + x[0]


@numba.njit(JAC_SIGNATURE)
def bautin_jac(x, mu, th, out):
    r2 = x[0] ** 2 + x[1] ** 2
    g = mu + th[0] * r2 - r2**2
    d0 = (th[0] - 2 * r2) * 2 * x[0]
    d1 = (th[0] - 2 * r2) * 2 * x[1]
    out[0, 0] = g + x[0] * d0
    out[0, 1] = x[0] * d1 - 1
    out[1, 0] = x[1] * d0 + 1
    out[1, 1] = g + x[1] * d1


@numba.njit(F_SIGNATURE)
def bautin_dfdp(x, mu, th, out):
    out[0] = x[0]
    out[1] = x[1]


@pytest.fixture(scope="module")
def system():
    return compiled_system(bautin_f, bautin_jac, bautin_dfdp, 2, theta=[1.0], parameter_name="mu")  # beta = 1


def test_compiled_flow_matches_scipy_flow(system, rng):
    cf, sf = CompiledFlow(system), ScipyFlow(system)
    assert cf.method == "DOP853-jit"
    for _ in range(3):
        x0 = rng.normal(size=2) * 0.8
        mu = float(rng.uniform(-0.3, 0.3))
        a, b = cf(x0, 5.0, mu, n_samples=16), sf(x0, 5.0, mu, n_samples=16)
        np.testing.assert_allclose(a.x, b.x, atol=1e-10)
        np.testing.assert_allclose(a.monodromy, b.monodromy, atol=1e-9)
        np.testing.assert_allclose(a.dp, b.dp, atol=1e-9)
        np.testing.assert_allclose(a.x_samples, b.x_samples, atol=1e-10)
        c = cf(x0, 5.0, mu, sensitivities=False)
        np.testing.assert_allclose(c.x, a.x, atol=1e-10)
        assert c.monodromy is None


def test_compiled_continuation_finds_the_bautin_fold(system):
    """Same closed form as test_nl_continuation: fold of cycles at mu = -1/4, r^2 = 1/2."""
    h = first_lyapunov(system, [0.0, 0.0], 0.0)
    br = continue_cycles(system, h, (-0.5, 0.5), flow=CompiledFlow(system), ds_max=0.05)
    lpc = [sp for sp in br.special if sp.kind == "LPC"]
    assert len(lpc) == 1 and lpc[0].p == pytest.approx(-0.25, abs=1e-9)
    assert lpc[0].amplitude[0] ** 2 == pytest.approx(0.5, abs=1e-8)
    assert br.hysteresis_range == pytest.approx((-0.25, 0.0), abs=1e-9)
    o = find_periodic_orbit(system, [1.0, 0.0], period=6.0, p=0.1, flow=CompiledFlow(system))
    r2 = (1 + math.sqrt(1.4)) / 2
    assert o.floquet[0].real == pytest.approx(math.exp(2 * math.pi * (2 * r2 - 4 * r2**2)), rel=1e-8)


def test_theta_reaches_the_kernels(system):
    """beta = theta[0] = 0 makes the Hopf point degenerate (l1 = 0); beta = 1 gives l1 = 2 (test_nl_hopf)."""
    f, jac, dfdp = system._kernels
    s0 = compiled_system(f, jac, dfdp, 2, theta=[0.0])
    assert first_lyapunov(s0, [0.0, 0.0], 0.0).criticality == "degenerate"
    assert first_lyapunov(system, [0.0, 0.0], 0.0).l1 == pytest.approx(2.0, rel=1e-8)
    a = CompiledFlow(system, theta=[0.0])(np.array([0.5, 0.0]), 1.0, 0.1, sensitivities=False)
    b = ScipyFlow(s0)(np.array([0.5, 0.0]), 1.0, 0.1, sensitivities=False)
    np.testing.assert_allclose(a.x, b.x, atol=1e-10)


def test_compiled_flow_needs_kernels(system):
    from brakesqueal.nonlinear import SmoothSystem

    plain = SmoothSystem(system.f, system.jac, 2)
    with pytest.raises(ParameterError, match="kernels"):
        CompiledFlow(plain)
    with pytest.raises(ParameterError, match="rtol"):
        CompiledFlow(system, rtol=1.0)
