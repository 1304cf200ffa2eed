"""Shooting, Floquet multipliers and flows: closed-form orbits, long simulations, independent integrators."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from _nl_systems import bautin, brusselator, van_der_pol
from scipy.integrate import solve_ivp

from brakesqueal.errors import ParameterError
from brakesqueal.nonlinear import ScipyFlow, ShootingError, find_periodic_orbit, first_lyapunov, floquet_multipliers


@pytest.fixture(scope="module")
def vdp():
    return van_der_pol()


def test_bautin_orbit_and_multiplier_closed_form():
    """r' = r (mu + r^2 - r^4), theta' = 1: the cycle is a circle of radius r, T = 2 pi, first harmonic of
    x1 = r, and the non-trivial multiplier exp(2 pi (2 r^2 - 4 r^4)) (linearisation of r' at the cycle)."""
    s = bautin()
    for mu, r2 in ((-0.2, (1 + math.sqrt(1 - 0.8)) / 2), (-0.2, (1 - math.sqrt(1 - 0.8)) / 2), (0.3, (1 + math.sqrt(2.2)) / 2)):
        r = math.sqrt(r2)
        o = find_periodic_orbit(s, [r * 1.01, 0.02], period=6.2, p=mu)
        assert o.period == pytest.approx(2 * math.pi, rel=1e-10)
        np.testing.assert_allclose(o.amplitude, [r, r], rtol=1e-9)
        assert np.max(np.abs(np.hypot(o.samples[:, 0], o.samples[:, 1]) - r)) < 1e-9
        assert o.floquet[0] == pytest.approx(math.exp(2 * math.pi * (2 * r2 - 4 * r2**2)), rel=1e-8)
        assert o.trivial_multiplier_error < 1e-8
        assert o.stable == (r2 > 0.5)
        assert o.monodromy_method == "variational"


@pytest.mark.parametrize("system,x0,p0", [(van_der_pol, [0.0, 0.0], 0.0), (lambda: brusselator(1.0), [1.0, 2.0], 2.0)])
def test_amplitude_ratio_tends_to_one_near_a_supercritical_hopf(system, x0, p0):
    """Shooting from the normal-form guess: the computed first-harmonic amplitudes over the prediction
    a_j sqrt(dp) tend to 1 linearly in dp (the normal-form truncation error is O(dp))."""
    s = system()
    h = first_lyapunov(s, x0, p0)
    errs = []
    for dp in (1e-2, 1e-3, 1e-4):
        o = find_periodic_orbit(s, h.cycle_guess(h.p0 + dp))
        ratio = o.amplitude / h.amplitude(h.p0 + dp)
        errs.append(float(np.max(np.abs(ratio - 1))))
        assert o.period == pytest.approx(h.period(h.p0 + dp), rel=5 * dp)
        assert o.stable
    assert errs[1] < 0.2 * errs[0] and errs[2] < 0.2 * errs[1]
    assert errs[2] < 1e-3


def test_orbit_reproduces_itself_in_a_long_simulation(vdp):
    """Independent check: plain solve_ivp (RK45 and DOP853, no sensitivities) over 40 periods returns to the
    shooting orbit, and a perturbed start converges to it at the rate of the non-trivial multiplier."""
    o = find_periodic_orbit(vdp, [2.0, 0.0], period=6.6, p=1.0)
    assert o.trivial_multiplier_error < 1e-8
    fun = lambda t, y: vdp.f(y, 1.0)  # noqa: E731
    sol = solve_ivp(fun, (0, 40 * o.period), o.x[0], method="DOP853", rtol=1e-12, atol=1e-12)
    assert np.max(np.abs(sol.y[:, -1] - o.x[0])) < 1e-7
    # a perturbed start: its returns to the Poincare section through x0 converge to x0, their spacing to T
    f0 = vdp.f(o.x[0], 1.0)

    def section(t, y):
        return float(f0 @ (y - o.x[0]))

    section.direction = 1
    y1 = o.x[0] + np.array([0.05, -0.02])
    sol = solve_ivp(fun, (0, 10.5 * o.period), y1, method="RK45", rtol=1e-11, atol=1e-13, events=section)
    te, ye = sol.t_events[0], sol.y_events[0]
    assert te.size >= 10
    assert np.max(np.abs(ye[-1] - o.x[0])) < 1e-8
    assert te[-1] - te[-2] == pytest.approx(o.period, rel=1e-8)


def test_multiple_shooting_and_fd_monodromy_agree_with_single_shooting(vdp):
    o1 = find_periodic_orbit(vdp, [2.0, 0.0], period=6.6, p=1.0)
    o4 = find_periodic_orbit(vdp, [2.0, 0.0], period=6.6, p=1.0, n_segments=4)
    assert o4.x.shape == (4, 2)
    assert o4.period == pytest.approx(o1.period, rel=1e-10)
    assert o4.floquet[0] == pytest.approx(o1.floquet[0], rel=1e-8)
    ofd = find_periodic_orbit(vdp, [2.0, 0.0], period=6.6, p=1.0, flow=ScipyFlow(vdp, monodromy="finite-difference"))
    assert ofd.monodromy_method == "finite-difference"
    assert ofd.period == pytest.approx(o1.period, rel=1e-9)
    assert abs(ofd.floquet[0] - o1.floquet[0]) < 1e-6 * np.linalg.norm(o1.monodromy)
    np.testing.assert_allclose(ofd.monodromy, o1.monodromy, atol=1e-6 * np.linalg.norm(o1.monodromy))


def test_flow_sensitivities_against_finite_differences(vdp, rng):
    """Variational monodromy and d phi / d p against central differences of plain flows (random points)."""
    fl = ScipyFlow(vdp, rtol=1e-12)
    for _ in range(3):
        x0 = rng.normal(size=2)
        p = float(rng.uniform(0.1, 1.5))
        r = fl(x0, 2.0, p)
        h = 1e-5
        M = np.column_stack([(fl(x0 + h * e, 2.0, p, sensitivities=False).x - fl(x0 - h * e, 2.0, p, sensitivities=False).x)
                             / (2 * h) for e in np.eye(2)])  # fmt: skip
        dp = (fl(x0, 2.0, p + h, sensitivities=False).x - fl(x0, 2.0, p - h, sensitivities=False).x) / (2 * h)
        np.testing.assert_allclose(r.monodromy, M, rtol=1e-6, atol=1e-7)
        np.testing.assert_allclose(r.dp, dp, rtol=1e-6, atol=1e-7)
        np.testing.assert_allclose(r.f_end, vdp.f(r.x, p))


def test_floquet_multipliers_deflation_keeps_pairs():
    """Reduced monodromy: a matrix with eigenvector f0 for 1 and a complex pair; the pair comes out intact."""
    rng = np.random.default_rng(3)
    V = rng.normal(size=(3, 3))
    D = np.array([[1.0, 0, 0], [0, 0.3, -0.8], [0, 0.8, 0.3]])
    M = V @ D @ np.linalg.inv(V)
    allm, red, err = floquet_multipliers(M, V[:, 0])
    np.testing.assert_allclose(np.sort_complex(red), np.sort_complex([0.3 - 0.8j, 0.3 + 0.8j]), atol=1e-12)
    assert err < 1e-12 and allm.size == 3


def test_minimal_period_and_settle(vdp):
    o = find_periodic_orbit(vdp, [2.0, 0.0], period=3 * 6.66, p=1.0)  # converges to the orbit traversed 3 times
    assert o.period == pytest.approx(6.6632868593, rel=1e-9)
    o2 = find_periodic_orbit(vdp, [0.1, 0.0], period=8.0, p=1.0, settle=30)
    assert o2.period == pytest.approx(o.period, rel=1e-10)


def test_bad_inputs(vdp):
    with pytest.raises(ParameterError, match="period"):
        find_periodic_orbit(vdp, [1.0, 0.0])
    with pytest.raises(ParameterError, match="shape"):
        find_periodic_orbit(vdp, [1.0, 0.0, 0.0], period=6.0, p=1.0)
    with pytest.raises(ParameterError, match="equilibrium"):
        find_periodic_orbit(vdp, [0.0, 0.0], period=6.0, p=1.0)
    with pytest.raises(ShootingError):
        find_periodic_orbit(vdp, [1e-3, 0.0], period=6.3, p=-0.5, max_iter=6)  # no cycle: the focus is stable



class _NoisyFlow:
    """A flow whose end state carries relative noise of its ``rtol`` (as event location leaves in a piecewise flow)."""

    def __init__(self, inner: ScipyFlow) -> None:
        self.inner, self.system, self.rtol = inner, inner.system, inner.rtol
        self.rng = np.random.default_rng(20261129)

    def __call__(self, x0, T, p, **kw):
        r = self.inner(x0, T, p, **kw)
        return dataclasses.replace(r, x=r.x * (1 + self.rtol * self.rng.uniform(-1, 1, r.x.shape)))


@pytest.mark.parametrize("rtol", [1e-6, 1e-8])
@pytest.mark.parametrize("mu", [-0.2, 0.3])
def test_newton_stops_at_the_flows_noise_floor_on_the_closed_form_cycle(rtol, mu):
    """Noise of the flow's rtol in every end state and a tol it cannot reach (1e-13): Newton stops once the
    residual is at that noise floor and the update no longer shrinks, on the Bautin circle (closed form as
    above) to the accuracy the flow allows; it does not stop there after two iterations from 1 % away."""
    s = bautin()
    r = math.sqrt((1 + math.sqrt(1 + 4 * mu)) / 2)  # the stable (outer) circle
    flow = _NoisyFlow(ScipyFlow(s, rtol=rtol))
    o = find_periodic_orbit(s, [r * 1.01, 0.02], period=6.2, p=mu, flow=flow, tol=1e-13)
    assert o.residual <= 10 * rtol
    assert o.period == pytest.approx(2 * math.pi, rel=1e3 * rtol)
    assert np.max(np.abs(np.hypot(o.samples[:, 0], o.samples[:, 1]) - r)) < 1e3 * rtol
    with pytest.raises(ShootingError):
        find_periodic_orbit(s, [r * 1.01, 0.02], period=6.2, p=mu, flow=flow, tol=1e-13, max_iter=2)
