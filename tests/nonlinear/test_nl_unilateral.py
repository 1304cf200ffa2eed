"""Periodic orbits of a brake model through contact loss and re-contact (issue 14, unilateral contact).

Independent checks:
* the orbit found by shooting with the piecewise flow (``model_piecewise_system``: SciPy's DOP853 with
  event location and saltation matrices) against a long event-driven simulation with the compiled
  integrator (``simulate(..., contact="unilateral")``, its own event location and switching): the
  simulation started on the orbit returns to it every period, its lift-off/re-contact times repeat with
  the orbit's, and the contact duty cycle from the simulation's events equals the orbit's;
* the energy balance over one period: the work of the supports, dampers and contact forces on the disk, from
  kinematics and forces written in the test, sums to zero (the friction's input equals the dampers' loss).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from brakesqueal import Axis
from brakesqueal.model import ParameterSpace
from brakesqueal.nonlinear import find_periodic_orbit
from brakesqueal.nonlinear.squeal import _duty_cycle
from brakesqueal import hopf_points, model_piecewise_system, model_system
from brakesqueal import simulate

from _disk_energy import disk_work

P_LIFT = 36.045  # Omega [rad/s]: 0.44 rad/s past the Fig. 3 onset, the pads lift off for ~5 % of the period


@pytest.fixture(scope="module")
def lifting_orbit():
    space = ParameterSpace.from_preset("paper-fig3", {"mu1": 0.5, "mu2": 0.5, "k_ip": math.inf})
    hp = hopf_points(space, Axis("Omega", 30.0, 40.0))[0].hopf
    smooth = find_periodic_orbit(model_system(space, "Omega"), hp.cycle_guess(36.03), tol=1e-9)
    pw = model_piecewise_system(space, "Omega")
    o = find_periodic_orbit(pw, smooth.x[0], period=smooth.period, p=P_LIFT, tol=1e-8, n_samples=256)
    return space, pw, o


@pytest.mark.slow
def test_orbit_through_contact_loss_matches_event_driven_simulation(lifting_orbit):
    space, pw, o = lifting_orbit
    names = sorted(e.name for e in o.events)
    assert names == ["contact-loss-pad-1", "contact-loss-pad-2", "re-contact-pad-1", "re-contact-pad-2"]
    assert o.trivial_multiplier_error < 1e-6 and o.stable
    T = o.period
    params = space.resolve({"Omega": P_LIFT})
    n_per = 100
    tr = simulate(params, n_per * T, x0=o.x[0], rtol=1e-11, events="continue", contact="unilateral",
                  sample_rate=16 / T)
    assert tr.status == "finished"
    returns = tr.y[::16]
    scale = np.abs(o.samples).max(axis=0)
    assert np.all(np.abs(returns - o.x[0]) <= 1e-7 * scale)
    # the switching times repeat with the orbit's every period
    for e in o.events:
        ts = np.asarray(tr.event_times[e.name])
        k = np.round((ts - e.t) / T)
        assert ts.size >= n_per - 1
        assert np.abs(ts - e.t - k * T).max() < 1e-8 * T
    # duty cycle: from the simulation's events over the last 50 periods vs the orbit's events
    t0 = (n_per - 50) * T
    for j, pad in enumerate(("1", "2")):
        off_start = np.asarray(tr.event_times[f"contact-loss-pad-{pad}"])
        on = np.asarray(tr.event_times[f"re-contact-pad-{pad}"])
        sel = (off_start >= t0) & (off_start < n_per * T)
        off = sum(on[on > s][0] - s for s in off_start[sel] if (on > s).any())
        duty_sim = 1 - off / (50 * T)
        duty = _duty_cycle(o, int(o.sample_modes[0]), 2)[j]
        assert 0.9 < duty < 0.99
        assert duty_sim == pytest.approx(duty, abs=1e-6)



def test_energy_balance_over_one_period(lifting_orbit):
    """Over one period the disk's energy T - Omega L_z0 returns to its value, so the power of the external moments
    (supports, support dampers, pads' contact forces; the drive's torque along z0 does no work on w) integrates to 0.

    Independent of the equations' assembly: the Cardan kinematics (q1 about x0, q2 about y1, the spin rate from the
    constraint, eq. 40), the contact points and the contact forces f_p = F_n (s z3 + mu v_r/|v_r|) are written here
    from the trajectory's outputs (acting F_n, v_r, h).  d/dt (T - Omega L_z0) = w . m with w = omega - Omega z0.
    """
    space, pw, o = lifting_orbit
    params = space.resolve({"Omega": P_LIFT})
    N = 20000
    tr = simulate(params, o.period, x0=o.x[0], rtol=1e-12, events="continue", contact="unilateral",
                  sample_rate=N / o.period * (1 + 1e-12))
    assert tr.t.size == N + 1 and tr.engaged is not None and not tr.engaged.all()  # the pads lift off
    work = disk_work(params, tr)
    assert work["contact"] > 0 and work["damper"] < 0  # friction feeds the squeal, the damper takes it out
    assert abs(sum(work.values())) < 1e-6 * work["contact"], work  # measured 4e-8 (trapezoid rule across kinks)
    # a wrong sign of the contact moment would not balance (the check can fail)
    assert abs(work["support"] + work["damper"] - work["contact"]) > 1.0 * work["contact"]
