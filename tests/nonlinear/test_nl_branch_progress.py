"""Progress reports and cancel of the limit-cycle branches (``progress=`` of ``continue_cycles``,
``squeal_branch`` and ``harmonic_branch``; the explorer's Cancel raises from it).

The expected fractions are recomputed here from the returned branch alone, by the documented rule: after the
k-th branch point the running maximum of ``k / max_points`` and of ``(p_k - p_0) / (p_far - p_0)`` (``p_0``
the start, ``p_far`` the end of the range the branch heads for), clipped to ``[0, 1]``; the last fraction
again before each step that locates the contact loss; 1.0 at the end.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from _nl_systems import bautin

from brakesqueal import Axis
from brakesqueal.errors import ParameterError
from brakesqueal.model.parameters import ParameterSpace
from brakesqueal.nonlinear import continue_cycles, find_periodic_orbit, first_lyapunov
from brakesqueal import harmonic_branch
from brakesqueal.nonlinear.models import cycle_route

#: paper-fig3 at mu1 = mu2 = 0.5: Hopf point at Omega ~ 35.6 (rigid pads) / 35.74 (k_ip = 1e8), a pad loses
from brakesqueal import squeal_branch
#: contact near 36.04 / 36.19 (test_nl_models, test_nl_harmonic); the ranges end just past it, so both the
#: distance in the parameter and the located contact loss take part
RIGID = {"mu1": 0.5, "mu2": 0.5, "k_ip": math.inf}
SOFT = {"mu1": 0.5, "mu2": 0.5}
SHOOT_AXIS = Axis("Omega", 30.0, 36.2)
HB_AXIS = Axis("Omega", 30.0, 36.3)


class Stop(Exception):
    """A progress callback's own exception (like the explorer's ``Cancelled``)."""


def expected(p: np.ndarray, p0: float, p_far: float, max_points: int) -> list[float]:
    """The fraction after each branch point, by the documented rule."""
    out, best = [], 0.0
    for k, pk in enumerate(p, start=1):
        best = max(best, min(1.0, max(0.0, k / max_points, (pk - p0) / (p_far - p0))))
        out.append(best)
    return out


def well_formed(calls: list[float], n_points: int) -> None:
    f = np.asarray(calls)
    assert f.size >= n_points
    assert np.all((f >= 0) & (f <= 1)) and np.all(np.diff(f) >= 0) and f[-1] == 1.0


def stopper(at: int, calls: list[float]):
    def progress(fraction: float) -> None:
        calls.append(fraction)
        if len(calls) == at:
            raise Stop(f"stop at call {at}")

    return progress


@pytest.fixture(scope="module")
def bautin_hopf():
    s = bautin()
    return s, first_lyapunov(s, [0.0, 0.0], 0.0)


@pytest.mark.slow
def test_continue_cycles_reports_the_running_maximum_through_a_fold(bautin_hopf):
    """r' = r (mu + r^2 - r^4): subcritical Hopf at mu = 0, the branch heads for mu = -0.5, turns at the fold
    mu = -1/4 and ends at mu = +0.5: after the fold the distance towards -0.5 shrinks, the fraction does not."""
    s, h = bautin_hopf
    calls: list[float] = []
    br = continue_cycles(s, h, (-0.5, 0.5), ds_max=0.1, max_points=80, progress=calls.append)
    p = br.data["p"].values
    assert [k.kind for k in br.special] == ["H", "LPC", "EP"] and br.status == "range"
    assert len(calls) == p.size + 1  # one per point, then 1.0
    assert calls[:-1] == pytest.approx(expected(p, 0.0, -0.5, 80), rel=1e-12, abs=1e-15)
    well_formed(calls, p.size)
    raw = -p / 0.5
    turn = int(np.argmin(p))
    assert raw[-2] < raw[turn] - 0.2 and calls[-2] == pytest.approx(max(raw[turn], p.size / 80))


def test_continue_cycles_from_an_orbit_heads_for_the_end_of_its_direction(bautin_hopf):
    s, _ = bautin_hopf
    r2 = (1 + math.sqrt(1 + 4 * 0.1)) / 2
    o = find_periodic_orbit(s, [math.sqrt(r2), 0.0], period=6.3, p=0.1)
    calls: list[float] = []
    br = continue_cycles(s, o, (-0.3, 0.2), direction=-1, ds_max=0.1, max_points=60, progress=calls.append)
    p = br.data["p"].values
    assert len(calls) == p.size + 1
    assert calls[:-1] == pytest.approx(expected(p, o.p, -0.3, 60), rel=1e-12, abs=1e-15)
    well_formed(calls, p.size)


def test_continue_cycles_stops_when_progress_raises(bautin_hopf):
    s, h = bautin_hopf
    calls: list[float] = []
    with pytest.raises(Stop, match="call 3"):
        continue_cycles(s, h, (-0.5, 0.5), ds_max=0.1, progress=stopper(3, calls))
    assert len(calls) == 3
    with pytest.raises(ParameterError, match="'progress'") as err:
        continue_cycles(s, h, (-0.5, 0.5), progress=0.5)  # type: ignore[arg-type]
    assert err.value.parameter == "progress"


@pytest.fixture(scope="module")
def shooting_run():
    space = ParameterSpace.from_preset("paper-fig3", RIGID)
    assert cycle_route(space, SHOOT_AXIS) == "shooting"
    calls: list[float] = []
    b = squeal_branch(space, SHOOT_AXIS, max_points=60, progress=calls.append)
    return space, b, calls


@pytest.mark.slow
def test_shooting_branch_reports_its_points_and_the_location(shooting_run):
    _, b, calls = shooting_run
    p = b.data["p"].values
    h = b.hopf.hopf
    assert b.contact_loss is not None and b.branch.status == "range"
    well_formed(calls, p.size)
    far = SHOOT_AXIS.stop if h.side > 0 else SHOOT_AXIS.start
    exp = expected(p, h.p0, far, 60)
    assert calls[:p.size] == pytest.approx(exp, rel=1e-12, abs=1e-15)
    assert max(exp) > 0.9 and exp[-2] > (p.size - 1) / 60 + 0.3  # the distance term decided it
    # then the continuation's 1.0, the location of the contact loss (at least one shooting) and the end
    assert len(calls) >= p.size + 3 and set(calls[p.size:]) == {1.0}


@pytest.mark.slow
def test_shooting_branch_stops_when_progress_raises(shooting_run):
    space, b, calls = shooting_run
    seen: list[float] = []
    with pytest.raises(Stop):
        squeal_branch(space, SHOOT_AXIS, max_points=60, progress=stopper(3, seen))
    assert len(seen) == 3
    # in the location of the contact loss: the first report after the continuation's own 1.0
    at = b.data["p"].size + 2
    seen = []
    with pytest.raises(Stop):
        squeal_branch(space, SHOOT_AXIS, max_points=60, progress=stopper(at, seen))
    assert len(seen) == at < len(calls)
    with pytest.raises(ParameterError, match="'progress'"):
        squeal_branch(space, SHOOT_AXIS, progress="report")  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def harmonic_run():
    space = ParameterSpace.from_preset("paper-fig3", SOFT)
    assert cycle_route(space, HB_AXIS) == "harmonic balance"
    calls: list[float] = []
    b = harmonic_branch(space, HB_AXIS, max_points=25, max_harmonics=40, progress=calls.append)
    return space, b, calls


def test_harmonic_branch_reports_its_points_and_the_location(harmonic_run):
    _, b, calls = harmonic_run
    p = np.array([pt.p for pt in b.points])
    h = b.hopf.hopf  # the exact normal form's Hopf point (the branch's start)
    assert b.status == "contact_loss" and b.points[-1].p == b.contact_loss
    well_formed(calls, p.size)
    assert h.side > 0
    exp = expected(p, h.p0, HB_AXIS.stop, 25)
    ticks = len(calls) - p.size - 1
    assert ticks >= 1  # the Illinois location of the contact loss reported
    # the points up to the last, the location's reports (the last fraction again), the located point, 1.0
    assert calls == pytest.approx(exp[:-1] + [exp[-2]] * ticks + [exp[-1], 1.0], rel=1e-12, abs=1e-15)
    assert max(exp) > p.size / 25 + 0.15  # the distance term decided it


def test_harmonic_branch_stops_when_progress_raises(harmonic_run):
    space, b, calls = harmonic_run
    for at in (3, len(b.points)):  # a branch point; the first step of the location of the contact loss
        seen: list[float] = []
        with pytest.raises(Stop):
            harmonic_branch(space, HB_AXIS, max_points=25, max_harmonics=40, progress=stopper(at, seen))
        assert len(seen) == at < len(calls)
    with pytest.raises(ParameterError, match="'progress'"):
        harmonic_branch(space, HB_AXIS, progress=[0.5])  # type: ignore[arg-type]
