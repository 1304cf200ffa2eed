"""Events along a squeal branch are located independently of the continuation's range and steps.

Paper model, Fig. 3 set with mu1 = mu2 = 0.5 and k_ip = 1e8 (onset 35.7408 rad/s): before the fix the contact loss
was 36.18 rad/s over Omega in [30, 40] but 36.52 over [0.36, 3600] (log path), whose first step jumped past it.
"""

from __future__ import annotations

import numpy as np
import pytest

from brakesqueal import Axis
from brakesqueal.model import ParameterSpace
from brakesqueal.nonlinear import find_periodic_orbit
from brakesqueal import model_system, squeal_branch

RUNS = [  # (range, options): narrow, wide linear, wide log; several max_points / step settings
    (Axis("Omega", 30.0, 40.0), {"max_points": 25}),
    (Axis("Omega", 0.36, 3600.0), {"max_points": 25}),
    (Axis("Omega", 0.36, 3600.0, log=True), {"max_points": 25}),
    (Axis("Omega", 30.0, 40.0), {"max_points": 40, "ds_max": 0.02}),
    (Axis("Omega", 35.0, 37.0), {"max_points": 20, "ds": 0.05, "ds_max": 0.1}),
]


@pytest.fixture(scope="module")
def branches():
    space = ParameterSpace.from_preset("paper-fig3", {"mu1": 0.5, "mu2": 0.5})
    return space, [squeal_branch(space, axis, **opts) for axis, opts in RUNS]


@pytest.mark.slow
def test_contact_loss_does_not_depend_on_range_or_steps(branches):
    _, runs = branches
    losses = np.array([b.contact_loss for b in runs], dtype=float)
    assert np.all(np.isfinite(losses))
    assert np.ptp(losses) < 1e-6, losses  # rad/s (measured spread 3e-9)
    onset = runs[0].hopf.branch_start.p0  # the branch continues the simulated (quasi-static pad) equations
    for k, b in enumerate(runs):
        assert b.summary.onset == pytest.approx(onset, rel=1e-13)  # the Hopf point, refined from range-dependent brackets
        # stable squeal from the onset up to the located contact loss, whatever the range (was (35.74, 35.74))
        assert b.summary.squeal_range == pytest.approx((onset, b.contact_loss), abs=1e-12)
        p = b.data["p"].values
        if k < 3:  # default steps: the branch resolves the range up to the event, whatever the requested range
            assert np.count_nonzero((p > onset) & (p < b.contact_loss)) >= 4


@pytest.mark.slow
def test_contact_loss_against_shooting_and_hopf_prediction(branches):
    """Independent: orbits shot at fixed Omega on either side of the loss (their raw smallest normal force over
    512 samples changes sign there), and the normal-form prediction F_min = F0 - k sqrt(Omega - Omega0)."""
    space, runs = branches
    b = runs[2]
    loss, onset = b.contact_loss, b.hopf.hopf.p0
    system = model_system(space, "Omega")
    sim = system.simulation_model
    ds = b.data
    i = int(np.argmin(np.abs(ds["p"].values - loss)))
    x, T = ds["orbit"].values[i][0], float(ds["period"].values[i])

    def fmin(q):
        o = find_periodic_orbit(system, x, period=T, p=q, tol=1e-10, n_samples=512)
        params = space.resolve({"Omega": q})
        st = sim.silent(params)
        return min(float(sim.contact_at(params, y, st)[:, 0].min()) for y in o.samples)

    N0 = 3000.0
    assert abs(fmin(loss)) < 1e-4 * N0  # the force grows about 3.4 N per 1e-3 rad/s here
    assert fmin(loss - 1e-3) > 0 > fmin(loss + 1e-3)
    # the leading-order prediction from the Hopf point is within 2 % of the distance to the onset (measured 0.9 %)
    pred = ds.attrs["contact_loss_predicted"]
    assert abs(pred - loss) < 0.02 * (loss - onset)
    # the same leading order from the implicit equations' normal form (nonlinear.implicit; an independent
    # implementation: generated contact functions along X(i omega0, phi), pads' rates kept, k_ip = 1e8)
    assert abs(b.hopf.contact_loss - loss) < 0.05 * (loss - onset)
