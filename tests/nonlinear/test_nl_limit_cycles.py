"""``limit_cycles``: the library call that takes the route ``brakesqueal cycles`` takes.

Each result is compared with a direct call of the route :func:`cycle_route` names (same options), so the
dispatcher can only pass if it picks that route and forwards the options unchanged; refusals name the option.
"""

from __future__ import annotations

import math

import pytest

from brakesqueal import Axis
from brakesqueal.errors import ParameterError
from brakesqueal.model.parameters import ParameterSpace
from brakesqueal.nonlinear.harmonic import HarmonicBranch
from brakesqueal import harmonic_branch
from brakesqueal.nonlinear.models import cycle_route
from brakesqueal.nonlinear.squeal import SquealBranch

#: paper-fig3 at mu1 = mu2 = 0.5 (onset ~35.6 rigid / 35.74 with k_ip = 1e8; contact loss near 36.04 / 36.19)
from brakesqueal import limit_cycles, squeal_branch
RIGID = {"mu1": 0.5, "mu2": 0.5, "k_ip": math.inf}
SOFT = {"mu1": 0.5, "mu2": 0.5}
AXIS = Axis("Omega", 30.0, 36.3)


def test_soft_coulomb_pads_take_harmonic_balance_like_the_command():
    space = ParameterSpace.from_preset("paper-fig3", SOFT)
    assert cycle_route(space, AXIS) == "harmonic balance"
    calls: list[float] = []
    b = limit_cycles(space, AXIS, max_points=12, max_harmonics=30, progress=calls.append)
    ref = harmonic_branch(space, AXIS, max_points=12, max_harmonics=30)
    assert isinstance(b, HarmonicBranch) and b.to_dict()["route"] == "harmonic balance"
    assert [pt.p for pt in b.points] == [pt.p for pt in ref.points]
    assert b.contact_loss == ref.contact_loss
    assert calls and calls[-1] == 1.0


def test_rigid_pads_take_shooting_and_quasi_static_is_asked_for_by_name():
    rigid = ParameterSpace.from_preset("paper-fig3", RIGID)
    b = limit_cycles(rigid, Axis("Omega", 30.0, 36.2), max_points=8)
    ref = squeal_branch(rigid, Axis("Omega", 30.0, 36.2), max_points=8)
    assert isinstance(b, SquealBranch) and b.to_dict()["route"] == "shooting"
    assert list(b.data["p"].values) == list(ref.data["p"].values)
    soft = ParameterSpace.from_preset("paper-fig3", SOFT)
    q = limit_cycles(soft, AXIS, pads="quasi-static", max_points=6)
    assert isinstance(q, SquealBranch) and q.hopf.simulated is not None  # the quasi-static pads, on request


@pytest.mark.parametrize("kwargs,name", [
    ({"harmonics": 8}, "harmonics"),                      # a harmonic-balance option on the shooting route
    ({"flow_method": "Radau"}, "flow_method"),            # a shooting option on the harmonic-balance route
    ({"bogus": 1}, "bogus"),
    ({"pads": "exact", "pad_slope": 1e-4}, "pads"),
    ({"contact": "unilateral"}, "pads"),                  # soft Coulomb pads through lift-off: a choice to make
])
def test_refusals_name_the_option(kwargs, name):
    space = ParameterSpace.from_preset("paper-fig3", RIGID if name == "harmonics" else SOFT)
    with pytest.raises(ParameterError) as e:
        limit_cycles(space, AXIS, **kwargs)
    assert e.value.parameter == name, e.value


@pytest.mark.slow
def test_a_weakly_nonlinear_hopf_point_starts_its_branch_closer_in():
    """Fig. 3's set with rigid pads at the upper re-stabilisation (Omega = 8419.2 rad/s, l1 = 2.8e-13): the
    normal form's first orbit at the usual amplitude is far out of range and Newton's method did not converge
    from it ("the first cycle near the Hopf point did not converge"); the default route now starts closer in and
    follows the branch to the contact loss, which harmonic balance with the exact pads locates independently."""
    from brakesqueal import Axis, limit_cycles, resolve_space

    space = resolve_space(None, "paper-fig3", None, ["k_ip=inf", "mu2=0.5", "mu1=0.5"])
    axis = Axis("Omega", 2000, 20000, 2)
    shot = limit_cycles(space, axis)
    assert type(shot).__name__ == "SquealBranch" and shot.contact_loss is not None
    hb = limit_cycles(space, axis, pads="exact", max_points=60, max_harmonics=40)
    assert type(hb).__name__ == "HarmonicBranch" and hb.contact_loss is not None
    assert shot.contact_loss == pytest.approx(hb.contact_loss, rel=1e-7)


def test_where_shooting_cannot_start_the_default_route_falls_back_to_harmonic_balance():
    """A slice of Fig. 3's set next to its generalised-Hopf point (rigid pads, Omega = 3221 rad/s, along mu1):
    the shooting route cannot start its first orbit there; ``limit_cycles`` (the one owner of the route) does not
    refuse a branch that harmonic balance with the exact pads computes, and says which route ran and why.  The
    contact loss it finds lies next to the subcritical Hopf point, on the side the normal form predicts."""
    from brakesqueal import hopf_points, resolve_space
    from brakesqueal.nonlinear.periodic import ShootingError

    space = resolve_space(None, "paper-fig3", None, ["k_ip=inf", "mu2=0.5", "Omega=3221.023016"])
    axis = Axis("mu1", 0.23, 0.26)
    with pytest.raises(ShootingError, match="first cycle near the Hopf point"):
        squeal_branch(space, axis)
    b = limit_cycles(space, axis)
    assert isinstance(b, HarmonicBranch) and b.to_dict()["route"] == "harmonic balance"
    assert b.message.startswith("shooting did not converge") and "harmonic balance with the exact pads" in b.message
    (h,) = [p for p in hopf_points(space, axis) if p.hopf is not None]
    assert h.hopf.criticality == "subcritical" and b.contact_loss is not None
    assert (b.contact_loss - h.value) * h.hopf.side > 0  # on the side where the normal form puts the cycles
    assert abs(b.contact_loss - h.value) < 1e-4 * h.value
    from typer.testing import CliRunner

    from brakesqueal.cli import app

    r = CliRunner().invoke(app, ["cycles", "--preset", "paper-fig3", "--set", "k_ip=inf", "--set", "mu2=0.5", "--set",
                                 "Omega=3221.023016", "--along", "mu1=0.23:0.26"])
    assert r.exit_code == 0, r.output
    assert "by harmonic balance" in r.output and "shooting did not converge" in r.output
