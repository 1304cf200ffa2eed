"""Shooting through switching events: piecewise-linear oscillators whose orbits are computed exactly by
matching the analytic solutions of each mode (closed forms + Brent's method in the tests)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq

from brakesqueal.nonlinear import (FlowError, PiecewiseSystem, ScipyFlow, SmoothSystem, Transition, continue_cycles,
                                   find_periodic_orbit, first_lyapunov)  # fmt: skip

ZETA, KC, CC, GAP = 0.05, 3.0, 0.6, 0.5  # negative damping 2 zeta, contact stiffness / damping, gap (= parameter p)
E1 = np.array([1.0, 0.0])


def gap_oscillator() -> PiecewiseSystem:
    """x'' - 2 zeta x' + x = 0 for x < g (free, self-excited); plus k_c (x - g) + c_c x' for x > g (contact).

    The vector field jumps across x = g (the contact damping), so the saltation matrix is not the identity.
    """
    free = SmoothSystem(lambda x, p: np.array([x[1], -x[0] + 2 * ZETA * x[1]]),
                        lambda x, p: np.array([[0.0, 1.0], [-1.0, 2 * ZETA]]), 2, dfdp=lambda x, p: np.zeros(2),
                        state_names=("x", "v"), parameter_name="g")  # fmt: skip
    cont = SmoothSystem(lambda x, p: np.array([x[1], -x[0] + 2 * ZETA * x[1] - KC * (x[0] - p) - CC * x[1]]),
                        lambda x, p: np.array([[0.0, 1.0], [-1.0 - KC, 2 * ZETA - CC]]), 2,
                        dfdp=lambda x, p: np.array([0.0, KC]), state_names=("x", "v"), parameter_name="g")  # fmt: skip
    h = lambda x, p: x[0] - p  # noqa: E731
    return PiecewiseSystem(
        modes=(free, cont),
        transitions=((Transition(h, 1, +1, guard_grad=lambda x, p: E1, guard_dp=lambda x, p: -1.0, name="contact"),),
                     (Transition(h, 0, -1, name="lift-off"),)),  # FD guard derivatives in this mode
        mode_of=lambda x, p: int(x[0] > p or (x[0] == p and x[1] > 0)),
        mode_names=("free", "contact"),
    )  # fmt: skip


def _first_root(fun, t_max, sign):
    ts = np.linspace(1e-9, t_max, 4001)
    vals = fun(ts)
    i = np.flatnonzero((sign * vals[:-1] < 0) & (sign * vals[1:] >= 0))[0]
    return brentq(fun, ts[i], ts[i + 1], xtol=1e-15, rtol=1e-15)


def free_phase(v0, g):
    """From (g, v0 < 0) with x'' - 2 zeta x' + x = 0 back to x = g: (time, velocity)."""
    wf = math.sqrt(1 - ZETA**2)
    A, B = g, (v0 - ZETA * g) / wf
    t = _first_root(lambda t: np.exp(ZETA * t) * (A * np.cos(wf * t) + B * np.sin(wf * t)) - g, 2 * math.pi / wf, +1)
    v = math.exp(ZETA * t) * ((ZETA * A + wf * B) * math.cos(wf * t) + (ZETA * B - wf * A) * math.sin(wf * t))
    return t, v


def contact_phase(v0, g):
    """From (g, v0 > 0) in contact back to x = g: (time, velocity)."""
    dl = (CC - 2 * ZETA) / 2
    wc = math.sqrt(1 + KC - dl**2)
    y0 = g - KC * g / (1 + KC)
    A, B = y0, (v0 + dl * y0) / wc
    t = _first_root(lambda t: np.exp(-dl * t) * (A * np.cos(wc * t) + B * np.sin(wc * t)) - y0, 2 * math.pi / wc, -1)
    v = math.exp(-dl * t) * ((-dl * A + wc * B) * math.cos(wc * t) + (-dl * B - wc * A) * math.sin(wc * t))
    return t, v


def gap_orbit_exact(g):
    """Fixed point of the return map on {x = g, v > 0}: (v*, T, t_contact, t_free, multiplier)."""

    def P(v):
        tc, v1 = contact_phase(v, g)
        tf, v2 = free_phase(v1, g)
        return v2, tc, tf

    vs = brentq(lambda v: P(v)[0] - v, 0.3 * g / 0.5, 3 * g / 0.5, xtol=1e-15, rtol=1e-15)
    _, tc, tf = P(vs)
    h = 1e-6
    mult = (P(vs + h)[0] - P(vs - h)[0]) / (2 * h)
    return vs, tc + tf, tc, tf, mult


@pytest.fixture(scope="module")
def gap():
    s = gap_oscillator()
    vs, T, tc, tf, mult = gap_orbit_exact(GAP)
    o = find_periodic_orbit(s, [GAP, 1.1 * vs], period=1.05 * T, p=GAP)
    return s, o, (vs, T, tc, tf, mult)


def test_gap_oscillator_orbit_and_multiplier_match_the_exact_solution(gap):
    s, o, (vs, T, tc, tf, mult) = gap
    assert o.period == pytest.approx(T, rel=1e-10)
    assert [e.name for e in o.events] == ["contact", "lift-off"] or [e.name for e in o.events] == ["lift-off", "contact"]
    # the phase point lies on the exact orbit: integrate the exact flow from (g, v*) and compare
    t_contact = [e.t for e in o.events if e.name == "contact"][0]
    assert o.events[0].x[0] == pytest.approx(GAP, abs=1e-12)
    assert abs(np.vdot(E1, [ev.x for ev in o.events if ev.name == "contact"][0]) - GAP) < 1e-12
    v_at_contact = [ev.x[1] for ev in o.events if ev.name == "contact"][0]
    assert v_at_contact == pytest.approx(vs, rel=1e-9)
    assert t_contact >= 0
    # Floquet multiplier: derivative of the exact return map, and Liouville (det S = 1 here:
    # grad h . f is v on both sides) mu = exp(2 zeta t_free - (c_c - 2 zeta) t_contact)
    assert o.floquet[0].real == pytest.approx(mult, rel=1e-7)
    assert o.floquet[0].real == pytest.approx(math.exp(2 * ZETA * tf - (CC - 2 * ZETA) * tc), rel=1e-9)
    assert o.trivial_multiplier_error < 1e-8
    assert o.stable
    # samples carry the mode: contact exactly where x > g
    np.testing.assert_array_equal(o.sample_modes == 1, o.samples[:, 0] > GAP)


def test_saltation_monodromy_against_finite_differences_of_the_event_driven_flow(gap):
    s, o, _ = gap
    var = ScipyFlow(s)(o.x[0], o.period, GAP)
    fd = ScipyFlow(s, monodromy="finite-difference", rtol=1e-12)(o.x[0], o.period, GAP)
    assert fd.monodromy_method == "finite-difference"
    np.testing.assert_allclose(var.monodromy, fd.monodromy, atol=1e-6)
    np.testing.assert_allclose(var.dp, fd.dp, atol=1e-6)  # p moves the guard and the contact force


def test_orbit_matches_a_long_independent_event_driven_simulation_and_energy_balance(gap):
    """Hand-written event loop on solve_ivp (DOP853): 80 periods from a perturbed start converge to the
    orbit; over one period the energy input of the negative damping equals the contact dissipation."""
    s, o, (vs, T, tc, tf, _) = gap
    free = lambda t, y: [y[1], -y[0] + 2 * ZETA * y[1]]  # noqa: E731
    cont = lambda t, y: [y[1], -y[0] + 2 * ZETA * y[1] - KC * (y[0] - GAP) - CC * y[1]]  # noqa: E731

    def hit(t, y):
        return y[0] - GAP

    hit.terminal = True
    t, y, mode, contacts = 0.0, np.array([GAP - 0.2, 0.3 * vs]), 0, []
    while t < 80 * T:
        hit.direction = 1 if mode == 0 else -1
        sol = solve_ivp(free if mode == 0 else cont, (t, 80 * T), y, method="DOP853", rtol=1e-12, atol=1e-13, events=hit)
        if sol.status != 1:
            break
        t, y = float(sol.t_events[0][0]), sol.y_events[0][0]
        if mode == 0:
            contacts.append((t, y[1]))
        mode = 1 - mode
    assert contacts[-1][1] == pytest.approx(vs, rel=1e-7)
    assert contacts[-1][0] - contacts[-2][0] == pytest.approx(o.period, rel=1e-7)
    # energy E = (x^2 + v^2)/2 + k_c (x - g)_+^2 / 2: dE/dt = 2 zeta v^2 - c_c v^2 [contact]
    dl, wc = (CC - 2 * ZETA) / 2, math.sqrt(1 + KC - ((CC - 2 * ZETA) / 2) ** 2)
    y0 = GAP - KC * GAP / (1 + KC)
    A, B = y0, (vs + dl * y0) / wc
    vc = lambda t: math.exp(-dl * t) * ((-dl * A + wc * B) * math.cos(wc * t) + (-dl * B - wc * A) * math.sin(wc * t))  # noqa: E731
    _, v1 = contact_phase(vs, GAP)
    wf = math.sqrt(1 - ZETA**2)
    Af, Bf = GAP, (v1 - ZETA * GAP) / wf
    vf = lambda t: math.exp(ZETA * t) * ((ZETA * Af + wf * Bf) * math.cos(wf * t) + (ZETA * Bf - wf * Af) * math.sin(wf * t))  # noqa: E731
    e_in = quad(lambda t: 2 * ZETA * vf(t) ** 2, 0, tf, epsabs=1e-14)[0] + quad(lambda t: 2 * ZETA * vc(t) ** 2, 0, tc)[0]
    e_out = quad(lambda t: CC * vc(t) ** 2, 0, tc, epsabs=1e-14)[0]
    assert e_in == pytest.approx(e_out, rel=1e-9)
    # the same balance from the shooting orbit's own samples (trapezoid over a fine resampling)
    fine = ScipyFlow(s)(o.x[0], o.period, GAP, sensitivities=False, n_samples=20000)
    v = fine.x_samples[:, 1]
    power = (2 * ZETA - CC * (np.asarray(fine.modes) == 1)) * v**2
    assert abs(power.mean()) * o.period < 1e-3 * e_in  # rectangle rule across the two jumps of the power


def test_continuation_in_the_gap_matches_the_exact_period():
    s = gap_oscillator()
    vs, T, *_ = gap_orbit_exact(GAP)
    o = find_periodic_orbit(s, [GAP, vs], period=T, p=GAP)
    br = continue_cycles(s, o, (0.3, 0.8), ds_max=0.2, max_points=12, detect=())
    g = br.data["p"].values
    assert np.ptp(g) > 0.1
    for gi, Ti in zip(g[::3], br.data["period"].values[::3]):
        assert Ti == pytest.approx(gap_orbit_exact(gi)[1], rel=1e-9)
    # the system is homogeneous of degree 1 in (x, g): amplitudes scale with g
    np.testing.assert_allclose(br.data["amplitude"].values[:, 0] / g, br.data["amplitude"].values[0, 0] / g[0], rtol=1e-6)


def test_impact_oscillator_reset_map_and_saltation():
    """Wall at x = g with restitution r: v+ = -r v-.  Return map from the closed form; Liouville with
    det S = r^2 gives mu = r^2 exp(2 zeta T)."""
    r, g = 0.8, 0.5
    free = SmoothSystem(lambda x, p: np.array([x[1], -x[0] + 2 * ZETA * x[1]]),
                        lambda x, p: np.array([[0.0, 1.0], [-1.0, 2 * ZETA]]), 2, dfdp=lambda x, p: np.zeros(2))  # fmt: skip
    wall = Transition(lambda x, p: x[0] - p, 0, +1, reset=lambda x, p: np.array([x[0], -r * x[1]]), name="impact")
    s = PiecewiseSystem((free,), ((wall,),), lambda x, p: 0)
    P = lambda v: -r * free_phase(v, g)[1]  # noqa: E731  (v < 0 just after the impact)
    vs = brentq(lambda v: P(v) - v, -5.0, -0.05, xtol=1e-15)
    T = free_phase(vs, g)[0]
    mult = (P(vs + 1e-6) - P(vs - 1e-6)) / 2e-6
    o = find_periodic_orbit(s, [0.0, -1.0], period=T, p=g, settle=5)
    assert o.period == pytest.approx(T, rel=1e-10)
    assert [e.name for e in o.events] == ["impact"]
    assert o.floquet[0].real == pytest.approx(mult, rel=1e-7)
    assert o.floquet[0].real == pytest.approx(r**2 * math.exp(2 * ZETA * T), rel=1e-9)
    assert o.trivial_multiplier_error < 1e-8


@pytest.mark.slow
def test_hopf_then_grazing_contact():
    """Van der Pol with a one-sided spring at x = g: the cycle born at the Hopf point grows until it grazes
    the contact; the GR point is located where the orbit's maximum reaches g."""
    kc, g = 4.0, 0.5
    fv = lambda x, mu: np.array([x[1], -x[0] + (mu - x[0] ** 2) * x[1]])  # noqa: E731
    jv = lambda x, mu: np.array([[0.0, 1.0], [-1 - 2 * x[0] * x[1], mu - x[0] ** 2]])  # noqa: E731
    dp = lambda x, mu: np.array([0.0, x[1]])  # noqa: E731
    free = SmoothSystem(fv, jv, 2, dfdp=dp, parameter_name="mu")
    cont = SmoothSystem(lambda x, mu: fv(x, mu) - np.array([0.0, kc * (x[0] - g)]),
                        lambda x, mu: jv(x, mu) - np.array([[0.0, 0.0], [kc, 0.0]]), 2, dfdp=dp, parameter_name="mu")  # fmt: skip
    h = lambda x, mu: x[0] - g  # noqa: E731
    pw = PiecewiseSystem((free, cont), ((Transition(h, 1, +1, name="contact"),), (Transition(h, 0, -1, name="lift-off"),)),
                         mode_of=lambda x, mu: int(x[0] > g))  # fmt: skip
    hopf = first_lyapunov(free, [0.0, 0.0], 0.0)
    br = continue_cycles(pw, hopf, (-0.1, 0.09), ds_max=0.2)
    gr = [sp for sp in br.special if sp.kind == "GR"]
    assert len(gr) == 1
    o = br.orbits[gr[0].index]
    fine = ScipyFlow(pw)(o.x[0], o.period, o.p, sensitivities=False, n_samples=8000)
    assert np.max(fine.x_samples[:, 0]) == pytest.approx(g, abs=1e-6)
    assert gr[0].p == pytest.approx(g**2 / 4, rel=0.02)  # amplitude ~ 2 sqrt(mu) (averaging)
    before = br.data["label"].values[: gr[0].index] == ""
    assert np.all(br.data["x_max"].values[: gr[0].index][before, 0] < g)


def test_sliding_is_reported_not_integrated():
    """x' = 1 for x < 0 and x' = -1 for x > 0 (with y' = 1): both fields push into x = 0 (Filippov sliding)."""
    a = SmoothSystem(lambda x, p: np.array([1.0, 1.0]), lambda x, p: np.zeros((2, 2)), 2)
    b = SmoothSystem(lambda x, p: np.array([-1.0, 1.0]), lambda x, p: np.zeros((2, 2)), 2)
    h = lambda x, p: x[0]  # noqa: E731
    s = PiecewiseSystem((a, b), ((Transition(h, 1, +1),), (Transition(h, 0, -1),)), lambda x, p: int(x[0] > 0))
    with pytest.raises(FlowError, match="sliding"):
        ScipyFlow(s)(np.array([-0.5, 0.0]), 2.0, 0.0)


@pytest.mark.parametrize("direction", [1, 0])
def test_shallow_crossing_inside_one_step_is_found(direction):
    """x'' = -x from (0, 1), amplitude 1; guard x - (1 - d) with d = 1e-7: the orbit
    is above the threshold for only 2 sqrt(2 d) ~ 9e-4 s, far shorter than a DOP853 step, so the sign test
    alone misses it.  Exact crossing times: arcsin(1 - d) and pi - arcsin(1 - d); the flow and its
    monodromy are those of the harmonic oscillator (both modes are the same field)."""
    d = 1e-7
    osc = SmoothSystem(lambda x, p: np.array([x[1], -x[0]]), lambda x, p: np.array([[0.0, 1.0], [-1.0, 0.0]]), 2)
    h = lambda x, p: x[0] - (1 - d)  # noqa: E731
    s = PiecewiseSystem((osc, osc), ((Transition(h, 1, direction, name="in"),),
                                     (Transition(h, 0, -direction, name="out"),)),
                        mode_of=lambda x, p: int(h(x, p) > 0))  # fmt: skip
    fr = ScipyFlow(s)(np.array([0.0, 1.0]), 3.0, 0.0)
    assert [e.name for e in fr.events] == ["in", "out"]
    # a crossing at slope sqrt(2 d) ~ 4.5e-4 is ill-conditioned in time: state error 1e-11 -> 2e-8 s
    assert fr.events[0].t == pytest.approx(math.asin(1 - d), abs=5e-8)
    assert fr.events[1].t == pytest.approx(math.pi - math.asin(1 - d), abs=5e-8)
    assert fr.events[0].x[0] == pytest.approx(1 - d, abs=1e-12)
    np.testing.assert_allclose(fr.x, [math.sin(3.0), math.cos(3.0)], atol=1e-10)
    np.testing.assert_allclose(fr.monodromy, [[math.cos(3.0), math.sin(3.0)], [-math.sin(3.0), math.cos(3.0)]], atol=1e-9)
