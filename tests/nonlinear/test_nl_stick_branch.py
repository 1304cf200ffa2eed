"""Limit-cycle branches with regularised stick-slip pads (``squeal_branch(pad_slope=S, stick_speed=V)``).

Independent checks: the branch of the ``stick`` law against the rising law's branch (the laws differ by
``mu V^2 / (2 v^2)`` away from stick, so the branches must agree to that order); the summary's treatment of
sliding reversals (end of validity for Coulomb/rising pads, ordinary motion with regularised stick-slip) on
the same branch data with the flag set.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from brakesqueal import Axis
from brakesqueal.cli import main
from brakesqueal.errors import ParameterError
from brakesqueal.model.options import resolve_space
from brakesqueal.nonlinear.squeal import SquealBranch, squeal_summary

#: paper-fig3 with soft pads and mu = 1: Hopf point at 29.14 rad/s, the pads approach stick on the cycles
from brakesqueal import squeal_branch
SETS = ["mu1=1", "mu2=1", "k_ip=1e6"]
AXIS = Axis("Omega", 29.0, 40.0)


@pytest.fixture(scope="module")
def branches():
    space = resolve_space(preset="paper-fig3", sets=SETS)
    rising = squeal_branch(space, AXIS, max_points=8, pad_slope=1e-4)
    stick = squeal_branch(space, AXIS, max_points=8, pad_slope=1e-4, stick_speed=1e-2)
    return rising, stick


@pytest.mark.slow
def test_stick_branch_agrees_with_the_rising_law_to_order_v_reg_squared(branches):
    rising, stick = branches
    assert stick.data.attrs["stick_slip"] == "regularised" and rising.data.attrs["stick_slip"] == "none"
    # v >= 1 m/s on these cycles, V = 1e-2 m/s: mu V^2 / (2 v^2) <= 5e-5 relative in the friction level
    onset_r, onset_s = rising.hopf.hopf.p0, stick.hopf.hopf.p0
    assert onset_s == pytest.approx(onset_r, rel=1e-4) and onset_s != onset_r
    # the amplitude grows like sqrt(p - p0): compare at the same distance from each branch's own onset
    p_s = stick.data["p"].values[1:]
    inside = p_s - onset_s + onset_r <= rising.data["p"].values.max()
    amp_r = np.interp(p_s[inside] - onset_s + onset_r, rising.data["p"].values, rising.data["tilt_amplitude"].values)
    assert inside.sum() >= 4
    np.testing.assert_allclose(stick.data["tilt_amplitude"].values[1:][inside], amp_r, rtol=2e-3)
    assert stick.summary.validity_end is None


@pytest.mark.slow
def test_a_sliding_reversal_ends_validity_only_without_stick_regularisation(branches):
    for br, ends in zip(branches, (True, False)):
        ds = br.data.copy()
        flags = np.zeros(ds["p"].size, dtype=bool)
        flags[3:] = True  # as if the cycles from the fourth point on had a pad's sliding reversed
        ds["sliding_reversal"] = ("point", flags)
        ds.attrs["validity_end"] = np.nan
        copy = SquealBranch(br.hopf, dataclasses.replace(br.branch, data=ds), br.contact_loss, br.pads, br.contact)
        s = squeal_summary(copy)
        assert (s.validity_end == pytest.approx(float(ds["p"].values[3]))) if ends else s.validity_end is None
        assert [r["sliding_reversal"] for r in s.table] == flags.tolist()


def test_stick_speed_needs_pad_slope(capsys):
    space = resolve_space(preset="paper-fig3", sets=SETS)
    with pytest.raises(ParameterError, match="stick_speed regularises the pads of pad_slope"):
        squeal_branch(space, AXIS, stick_speed=1e-3)
    assert main(["cycles", "--preset", "paper-fig3", "--set", "k_ip=1e6", "--along", "Omega=29:40",
                 "--stick-speed", "1e-3", "--format", "json"]) == 2
    assert "give --pad-slope too" in capsys.readouterr().err


@pytest.mark.slow
def test_cycles_command_with_stick_speed(capsys):
    assert main(["cycles", "--preset", "paper-fig3", *[a for s in SETS for a in ("--set", s)], "--along",
                 "Omega=29:40", "--pad-slope", "1e-4", "--stick-speed", "1e-2", "--max-points", "4",
                 "--format", "json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["summary"]["validity_end"] is None and d["summary"]["onset"] == pytest.approx(29.14, abs=0.01)
    assert d["points"] >= 2 and d["summary"]["criticality"] == "supercritical"
