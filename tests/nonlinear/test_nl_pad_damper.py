"""Limit cycles of pads with a tangential damper (``d_ip``): the pads' true rates kept, through lift-off.

``damped_pads`` gives the paper-fig3 pads (``mu = 0.5``, ``k_ip = 1e6``) a damper ``d_ip = 10 N s/m``; their
rates are then states of the explicit equations, determined at every normal force.  Two independent routes
compute the same branch of the same model:

* shooting with the compiled integrator and pseudo-arclength continuation (``squeal_branch``), which locates
  the contact loss as the ``GR`` point where the orbit's smallest ``F_n`` reaches 0;
* harmonic balance on the implicit equations with the exact generated Jacobian (``harmonic_branch``).

They must agree on the Hopf point and on the contact loss (measured 2026-11-27: 127.0314249 and 127.0314234
rad/s, 1.2e-8 relative).  With ``contact="unilateral"`` the shooting branch continues through lift-off; an orbit
past it reproduces itself in a simulation of the integrator's own event-driven unilateral contact.
"""

from __future__ import annotations

import numpy as np
import pytest

from brakesqueal import Axis
from brakesqueal.model.options import damped_pads, resolve_space
from brakesqueal import harmonic_branch
from brakesqueal import squeal_branch
from brakesqueal import simulate

from _disk_energy import disk_work

pytestmark = pytest.mark.slow  # module fixtures dominate: the whole module runs in `make test-slow`

SETS = ["mu1=0.5", "mu2=0.5", "k_ip=1e6"]
AXIS = Axis("Omega", 30.0, 140.0)


@pytest.fixture(scope="module")
def space():
    return damped_pads(resolve_space(preset="paper-fig3", sets=SETS), 10.0)


@pytest.fixture(scope="module")
def unilateral(space):
    return squeal_branch(space, AXIS, max_points=30, contact="unilateral")


def test_shooting_and_harmonic_balance_agree_on_the_contact_loss(space, unilateral):
    # stability=False: no Hill's-method Floquet exponents (90 % of this branch's time); they only decorate the
    # points with verdicts and steer neither the continuation, the harmonics nor the located contact loss,
    # which is all this test compares (the shooting check that does steer the harmonics still runs)
    hb = harmonic_branch(space, AXIS, max_points=60, stability=False)
    assert hb.status == "contact_loss", hb.message
    assert unilateral.hopf.branch_start is not None
    assert abs(hb.hopf.hopf.p0 - unilateral.hopf.branch_start.p0) < 1e-9 * hb.hopf.hopf.p0
    assert unilateral.contact_loss is not None and hb.contact_loss is not None
    assert abs(unilateral.contact_loss - hb.contact_loss) < 1e-6 * hb.contact_loss, (unilateral.contact_loss,
                                                                                     hb.contact_loss)
    assert unilateral.hopf.branch_start.criticality == "supercritical"


def test_the_unilateral_branch_continues_past_lift_off_and_an_orbit_reproduces_itself(space, unilateral):
    ds = unilateral.data
    p = ds["p"].values
    assert unilateral.contact_loss is not None and p.max() > unilateral.contact_loss + 1.0
    i = int(np.argmax(p))
    assert np.all(ds["duty_cycle"].values[i] < 0.99)  # both pads lift off for part of the period
    orbit = unilateral.branch.orbits[i]
    assert orbit.events  # the orbit's own lift-off and re-contact events
    params = space.resolve({"Omega": float(p[i])})
    tr = simulate(params, 5 * orbit.period, x0=orbit.x[0], rtol=1e-11, events="continue",
                  contact="unilateral", sample_rate=8 / orbit.period)
    assert tr.status == "finished", tr.message
    for pad in ("1", "2"):  # one lift-off and one re-contact per period and pad
        assert len(tr.event_times[f"contact-loss-pad-{pad}"]) == len(tr.event_times[f"re-contact-pad-{pad}"]) == 5
    y_end = tr.y[-1]
    scale = np.abs(orbit.x).max(axis=0)
    assert np.all(np.abs(y_end - orbit.x[0]) < 1e-5 * scale + 1e-12), (y_end, orbit.x[0])


def test_energy_balance_over_one_period_past_lift_off(space, unilateral):
    """Over one period of the orbit past lift-off the works of the supports, the support dampers and the pads'
    contact forces on the disk sum to zero (the disk's T - Omega L_z0 returns; kinematics and forces written in
    ``_disk_energy.py`` from the trajectory's outputs, the damped pads' deformations l included)."""
    p = unilateral.data["p"].values
    i = int(np.argmax(p))
    orbit = unilateral.branch.orbits[i]
    params = space.resolve({"Omega": float(p[i])})
    N = 20000
    tr = simulate(params, orbit.period, x0=orbit.x[0], rtol=1e-12, events="continue", contact="unilateral",
                  sample_rate=N / orbit.period * (1 + 1e-12))
    assert tr.t.size == N + 1 and tr.engaged is not None and not tr.engaged.all()  # the pads lift off
    work = disk_work(params, tr)
    assert work["contact"] > 0 and work["damper"] < 0, work
    assert abs(sum(work.values())) < 1e-5 * work["contact"], work


def test_the_damper_regularises_the_paper_pads_contact_loss_converges_as_it_vanishes():
    """As d_ip -> 0 the damped pads' Hopf point and contact loss tend to the undamped exact pads' (harmonic balance
    on both, the undamped one with the unregularised Coulomb pads): the damper is a regularisation of the paper's
    massless pads whose error vanishes (measured 2026-11-27: contact loss 128.17992 undamped; errors 1.15, 0.152,
    0.0329, 0.0080 rad/s at d_ip = 10, 3, 1, 0.3 N s/m, about first order), and unlike those pads it passes lift-off."""
    base = resolve_space(preset="paper-fig3", sets=SETS)
    axis = Axis("Omega", 30.0, 200.0)
    exact = harmonic_branch(base, axis, max_points=200, max_harmonics=200, stability=False)
    assert exact.status == "contact_loss"
    errors, onsets = [], []
    for d in (1.0, 0.3):
        # shooting_check=False: the check only cross-checks each orbit by integration (mismatch and monodromy
        # verdict); here the truncation error sets the harmonics (141), so the contact losses and onsets are
        # bit-identical without it (measured 2026-11-29) and the check cost 20 % of these two branches
        b = harmonic_branch(damped_pads(base, d), axis, max_points=200, max_harmonics=200, stability=False,
                            shooting_check=False)
        assert b.status == "contact_loss", b.message
        errors.append(abs(b.contact_loss - exact.contact_loss))
        onsets.append(abs(b.hopf.hopf.p0 - exact.hopf.hopf.p0))
    assert errors[1] < errors[0] / 2.5 and onsets[1] < onsets[0] / 2.5, (errors, onsets)
    assert errors[1] < 1e-4 * exact.contact_loss, errors
