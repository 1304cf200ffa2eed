"""Verified Floquet multipliers: the trivial multiplier, verdicts with an accuracy bound, Hill's method against the
monodromy, and the harmonics chosen until the residual and the shooting mismatch meet their tolerances.

Closed forms: the Hopf normal form ``z' = (mu + i omega) z - z |z|^2`` has the cycle ``|z|^2 = mu`` with the
non-trivial Floquet exponent ``-2 mu`` (multiplier ``exp(-4 pi mu / omega)``); a transverse direction
``w' = a w`` adds the exponent ``a`` exactly (multiplier ``exp(a T)``), which makes a multiplier as close to 1 as
wanted.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import sympy as sp
from _nl_systems import bautin, hopf_normal_form, sympy_system, van_der_pol

from brakesqueal import Axis, limit_cycles
from brakesqueal.codegen import build
from brakesqueal.errors import ParameterError
from brakesqueal.model.parameters import ParameterSpace
from brakesqueal.nonlinear import continue_cycles, find_periodic_orbit, first_lyapunov
from brakesqueal.nonlinear.floquet import cross_check, hill_exponents, multiplier_accuracy, stability_verdict
from brakesqueal.nonlinear.harmonic import harmonic_branch

RIGID = {"mu1": 0.5, "mu2": 0.5, "k_ip": math.inf}
SOFT = {"mu1": 0.5, "mu2": 0.5}


def _transverse(a: float):
    """The Hopf normal form (omega = 1, c = -1) with a transverse direction w' = a w: exponents -2 mu and a."""
    x1, x2, w, mu = sp.symbols("x1 x2 w mu", real=True)
    r2 = x1**2 + x2**2
    return sympy_system([mu * x1 - x2 - x1 * r2, x1 + mu * x2 - x2 * r2, sp.nsimplify(a) * w], [x1, x2, w], mu,
                        exact_multilinear=False, parameter_name="mu")


# ----------------------------------------------------------- closed forms and the verdict's bound
@pytest.mark.parametrize("mu", [0.05, 0.3])
def test_hill_and_monodromy_give_the_closed_form_exponent(mu):
    """Hopf normal form: monodromy multiplier exp(-2 mu T) and Hill exponent -2 mu, both stable; the trivial
    multiplier within 1e-9 of 1 by both methods."""
    s = hopf_normal_form(1.0, -1 + 0j)
    r = math.sqrt(mu)
    o = find_periodic_orbit(s, [r * 1.02, 0.0], period=2 * math.pi, p=mu)
    T = 2 * math.pi
    assert o.period == pytest.approx(T, rel=1e-10)
    assert o.floquet[0].real == pytest.approx(math.exp(-2 * mu * T), rel=1e-9)
    assert o.trivial_multiplier_error < 1e-9 and o.verdict == "stable"
    hill = hill_exponents(s, o, 8)
    assert hill.exponents[0].real == pytest.approx(-2 * mu, rel=1e-8)
    assert abs(hill.trivial) < 1e-9 and hill.trivial_multiplier_error < 1e-9
    assert hill.verdict == "stable" == cross_check(hill.verdict, o.verdict)
    assert hill.multipliers[0].real == pytest.approx(o.floquet[0].real, rel=1e-8)


@pytest.mark.parametrize("mu", [0.5, 1.5])
def test_hill_agrees_with_the_monodromy_on_van_der_pol(mu):
    """A strongly non-harmonic cycle: Hill's multiplier with 40 harmonics equals the monodromy's (to 1e-7) and
    the two verdicts agree, whatever the number of shooting segments."""
    s = van_der_pol()
    o1 = find_periodic_orbit(s, [2.0, 0.0], period=6.6, p=mu)
    o4 = find_periodic_orbit(s, [2.0, 0.0], period=6.6, p=mu, n_segments=4)
    hill = hill_exponents(s, o1, 40)
    assert abs(hill.multipliers[0] - o1.floquet[0]) < 1e-7 * max(1.0, abs(o1.floquet[0]))
    assert abs(o4.floquet[0] - o1.floquet[0]) < 1e-8
    assert o1.trivial_multiplier_error < 1e-8 and o4.trivial_multiplier_error < 1e-8
    assert hill.verdict == o1.verdict == o4.verdict == "stable"
    assert o4.multiplier_accuracy >= o1.multiplier_accuracy  # more segments: a larger bound


@pytest.mark.parametrize("a,expected", [(-0.1, "stable"), (0.1, "unstable"), (2e-14, "undecided"),
                                        (-2e-14, "undecided")])
def test_a_multiplier_near_one_is_undecided(a, expected):
    """A transverse multiplier exp(2 pi a): clearly inside or outside the unit circle gives a verdict; within the
    monodromy's accuracy of 1 (a = +-2e-14: |mu| - 1 ~ 1e-13, below 10 rtol) the point is undecided, whatever
    side the computed multiplier is on (``stable`` keeps the computed side)."""
    s = _transverse(a)
    o = find_periodic_orbit(s, [0.5, 0.0, 0.0], period=2 * math.pi, p=0.25)  # on the cycle: w = 0
    w = [m for m in o.floquet if abs(abs(m) - math.exp(-2 * 0.25 * 2 * math.pi)) > 1e-6]
    assert abs(w[0] - math.exp(2 * math.pi * a)) < 1e-10
    assert o.verdict == expected
    assert o.as_dict()["verdict"] == expected and o.as_dict()["multiplier_accuracy"] == o.multiplier_accuracy
    hill = hill_exponents(s, o, 6)
    if expected != "undecided":
        assert hill.verdict == expected
    else:  # the exponent a is below Hill's bound too
        assert hill.verdict == "undecided"


def test_the_fold_of_a_bautin_branch_is_undecided():
    """r' = r (mu + r^2 - r^4): the unstable cycles from the subcritical Hopf point turn at the fold mu = -1/4
    into stable ones; the located fold (LPC), where the second multiplier passes through 1, is undecided, and
    the points on either side keep their verdicts."""
    s = bautin()
    h = first_lyapunov(s, [0.0, 0.0], 0.0)
    br = continue_cycles(s, h, (-0.3, 0.05), ds_max=0.1, max_points=30, detect=("LPC",))
    d = br.data
    labels, verdicts = list(d["label"].values), list(d["verdict"].values)
    i = labels.index("LPC")
    assert d["p"].values[i] == pytest.approx(-0.25, abs=1e-9)
    assert verdicts[i] == "undecided"
    assert abs(d["largest_multiplier"].values[i] - 1) <= d["multiplier_accuracy"].values[i]
    assert verdicts[0] == "undecided" and set(verdicts[1:i]) == {"unstable"} and set(verdicts[i + 1:]) == {"stable"}


def test_verdict_rules_and_bad_input():
    assert multiplier_accuracy(1e-12, 1e-11) == pytest.approx(1e-10)
    assert multiplier_accuracy(1e-6, 1e-11) == pytest.approx(1e-5)
    assert multiplier_accuracy(1e-13, 1e-10, method="finite-difference") == pytest.approx(1e-5)
    assert multiplier_accuracy(math.nan) == math.inf
    assert stability_verdict([0.5, 1 - 1e-12], 1e-10) == "undecided"
    assert stability_verdict([0.5, 1 + 1e-6, 1 - 1e-12], 1e-10) == "unstable"
    assert stability_verdict([0.5j, 0.9], 1e-10) == "stable"
    assert cross_check("stable", None) == "stable"
    assert cross_check("stable", "unstable") == "undecided"
    assert cross_check(None, None) == "undecided"
    with pytest.raises(ParameterError, match="verdict"):
        cross_check("maybe")
    s = hopf_normal_form(1.0, -1 + 0j)
    o = find_periodic_orbit(s, [0.5, 0.0], period=2 * math.pi, p=0.25)
    with pytest.raises(ParameterError, match="harmonics"):
        hill_exponents(s, o, 0)
    with pytest.raises(ParameterError, match="n_samples"):
        hill_exponents(s, o, 4, n_samples=5)


# ----------------------------------------------------------- the paper's model
@pytest.fixture(scope="module")
def rigid():
    space = ParameterSpace.from_preset("paper-fig3", RIGID)
    return space, build(space.model)


def test_shooting_cycles_of_the_paper_model_report_the_trivial_multiplier(rigid, capsys):
    """paper-fig3 with rigid pads (shooting): every cycle's trivial multiplier within 1e-6 of 1 (in fact ~1e-11)
    and a verdict; the JSON of ``brakesqueal cycles`` carries both per point and the text says how many are
    undecided."""
    space, _ = rigid
    b = limit_cycles(space, Axis("Omega", 30.0, 36.2), max_points=6)
    ds = b.data
    cyc = ds["label"].values != "H"
    assert np.all(ds["trivial_multiplier_error"].values[cyc] < 1e-6)
    assert set(ds["verdict"].values[cyc]) <= {"stable", "unstable", "undecided"}
    assert ds["verdict"].values[0] == "undecided"  # the Hopf row: the critical pair on the unit circle
    big = ds["largest_multiplier"].values
    acc = ds["multiplier_accuracy"].values
    for v, m, a in zip(ds["verdict"].values[cyc], big[cyc], acc[cyc]):
        assert (v == "stable") == (m < 1 - a) and (v == "undecided") == (abs(m - 1) <= a)
    # near the onset the radial multiplier is 1 - O(1e-8): close calls, checked at a 100x smaller tolerance,
    # whose change (~1e-13) stays well inside the bound
    close = cyc & (np.abs(big - 1) < 1e4 * acc)
    assert close.any()
    assert np.all(ds["multiplier_change"].values[close] < 0.1 * acc[close])
    d = b.to_dict()
    assert [r["verdict"] for r in d["floquet"]] == list(ds["verdict"].values)
    assert all(r["verdict"] in ("stable", "unstable", "undecided") for r in d["summary"]["table"])
    from brakesqueal.cli import app
    from typer.testing import CliRunner

    args = ["cycles", "--preset", "paper-fig3", "--set", "mu1=0.5", "--set", "mu2=0.5", "--set", "k_ip=inf",
            "--along", "Omega=30:36.2", "--max-points", "4"]
    r = CliRunner().invoke(app, args + ["--format", "json"])
    assert r.exit_code == 0, r.output
    rows = json.loads(r.output)["floquet"]
    assert len(rows) == 4 and all(row["trivial_multiplier_error"] < 1e-6 for row in rows[1:])
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0 and "the trivial multiplier within" in r.output and "undecided" in r.output


def test_harmonic_balance_cross_checks_hill_with_the_monodromy(rigid):
    """Rigid pads allow shooting: every harmonic-balance orbit is integrated over one period by the simulated
    equations (mismatch ~1e-12), its monodromy's verdict is compared with Hill's, and the trivial exponent is
    the phase shift's (the radial exponent, nearly parallel to it near the onset, is kept: 2n - 1 = 3
    non-trivial exponents at every point)."""
    space, engine = rigid
    b = harmonic_branch(engine, space, Axis("Omega", 30.0, 36.2), max_points=6)
    for pt in b.points:
        assert pt.trivial_multiplier_error is not None and pt.trivial_multiplier_error < 1e-6
        assert pt.floquet_exponents is not None and len(pt.floquet_exponents) == 3
        assert pt.shooting_mismatch is not None and pt.shooting_mismatch < 1e-8
        assert pt.monodromy_verdict in ("stable", "undecided") and pt.hill_verdict == "stable"
        assert pt.verdict == cross_check(pt.hill_verdict, pt.monodromy_verdict)
        assert pt.to_dict()["verdict"] == pt.verdict
        # the monodromy's largest multiplier is exp(lambda_radial T) of Hill's radial exponent
        T = 2 * math.pi / pt.omega
        assert abs(pt.multipliers[0] - np.exp(pt.floquet_exponents[0] * T)) < 1e-7
    assert any(pt.verdict == "stable" for pt in b.points)


def test_harmonics_rise_until_the_residual_and_the_mismatch_meet_their_tolerances(rigid):
    """Soft Coulomb pads (harmonic balance): with a loose truncation tolerance the residual decides; a tight
    residual tolerance raises the harmonics where the orbit grows, below max_harmonics, and the residual falls
    below it.  Rigid pads (shooting possible): the shooting mismatch of the harmonic-balance orbit raises them
    too."""
    soft = ParameterSpace.from_preset("paper-fig3", SOFT)
    eng = build(soft.model)
    axis = Axis("Omega", 30.0, 36.3)
    loose = harmonic_branch(eng, soft, axis, max_points=8, harmonics=2, harmonic_tol=0.9, residual_tol=0.9)
    tight = harmonic_branch(eng, soft, axis, max_points=8, harmonics=2, harmonic_tol=0.9, residual_tol=1e-10)
    assert max(pt.residual for pt in loose.points) > 1e-8
    assert all(pt.residual <= 1e-10 for pt in tight.points)
    H = [pt.harmonics for pt in tight.points]
    assert H == sorted(H) and H[-1] > max(pt.harmonics for pt in loose.points) and H[-1] < 60
    assert tight.points[-1].residual < 1e-3 * loose.points[-1].residual
    assert all(pt.shooting_mismatch is None for pt in tight.points)  # soft Coulomb pads: no shooting check
    # rigid pads allow shooting: from one harmonic, with the truncation and residual tolerances out of the way,
    # the shooting mismatch alone raises the harmonics where it exceeds its tolerance (1e-9, floored at 1e3 rtol)
    space, engine = rigid
    kw = {"max_points": 8, "harmonics": 1, "harmonic_tol": 1.0, "residual_tol": 1.0}
    one = harmonic_branch(engine, space, Axis("Omega", 30.0, 36.2), shooting_check=False, **kw)
    b = harmonic_branch(engine, space, Axis("Omega", 30.0, 36.2), mismatch_tol=1e-9, **kw)
    assert all(pt.harmonics == 1 for pt in one.points)
    assert all(pt.shooting_mismatch <= 1e-8 for pt in b.points)
    raised = [pt for pt in b.points if pt.harmonics > 1]
    assert raised and b.points[0].harmonics == 1 and max(pt.harmonics for pt in b.points) < 60
    kept = [pt for pt in one.points if pt.p >= raised[0].p]
    assert all(pt.residual > 10 * raised[0].residual for pt in kept)  # one harmonic left a larger residual
    with pytest.raises(ParameterError, match="residual_tol"):
        harmonic_branch(engine, space, Axis("Omega", 30.0, 36.2), residual_tol=0.0)


@pytest.mark.slow
def test_a_200_point_branch_keeps_the_trivial_multiplier_at_one_and_hill_agrees_with_the_monodromy():
    """Issue 28's Floquet check on the paper's model (Fig. 3's set, rigid pads): along a 200-point shooting branch
    the trivial multiplier is within 1e-8 of 1 at every cycle; on the harmonic-balance branch of the same set
    (exact pads, which allow shooting here) Hill's verdict equals the monodromy's at every point, or the point
    says undecided."""
    from brakesqueal import resolve_space

    space = resolve_space(None, "paper-fig3", None, ["k_ip=inf", "mu2=0.5", "mu1=0.5"])
    axis = Axis("Omega", 30.0, 36.2)
    shot = limit_cycles(space, axis, max_points=200, ds_max=0.004)
    ds = shot.data
    assert ds["p"].size == 200
    cyc = ds["label"].values != "H"
    assert np.all(ds["trivial_multiplier_error"].values[cyc] < 1e-8)
    assert set(ds["verdict"].values[cyc]) <= {"stable", "unstable", "undecided"}
    hb = limit_cycles(space, axis, pads="exact", max_points=200).to_dict()["points"]
    both = [p for p in hb if p["hill_verdict"] is not None and p["monodromy_verdict"] is not None]
    assert len(both) >= 10
    for p in both:
        assert p["hill_verdict"] == p["monodromy_verdict"] or p["verdict"] == "undecided", p
        assert p["verdict"] in ("stable", "unstable", "undecided")
