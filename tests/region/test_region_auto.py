"""Side by side with AUTO-07p (issue 28 item 5): the paper's model exported as AUTO's C user functions, AUTO's
Hopf curve (HB on a one-parameter equilibrium branch, then ISW=2) against brakesqueal's, point by point.

Skipped, saying why, where AUTO-07p is not installed; in CI it must run (BRAKESQUEAL_REQUIRE_AUTO=1).
"""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

import brakesqueal as bs
from brakesqueal.analysis.maps import Axis
from brakesqueal.errors import BrakesquealError
from brakesqueal.region import correct_point, hopf_curves
from brakesqueal.region.auto import auto_available, auto_hopf_curve, auto_source, to_unit

#: Largest distance of an AUTO curve point from brakesqueal's curve, in units of the box's sides (log10 on a log
#: axis): AUTO's fort.7 prints 11 significant digits and solves to EPSL = EPSU = 1e-10.
CURVE_TOL = 1e-6
#: Largest distance of AUTO's generalised-Hopf point from ours (box units): AUTO's l1 is a finite difference
#: of third derivatives, located to EPSS = 1e-6.
GH_TOL = 1e-5


def _require_auto() -> None:
    why = auto_available()
    if why:
        if os.environ.get("BRAKESQUEAL_REQUIRE_AUTO") == "1":
            pytest.fail(f"BRAKESQUEAL_REQUIRE_AUTO=1 but {why}")
        pytest.skip(why)


def _distances(space, x: Axis, y: Axis, ac) -> np.ndarray:
    """Distance (box units) of every AUTO point to the nearest point of the Hopf curve (Newton from it)."""
    eng = bs.engine(space)
    out = []
    for xa, ya in zip(ac.x, ac.y):
        xm, ym, _ = correct_point(eng, space, x, y, float(xa), float(ya), hold="nearest")
        out.append(max(abs(to_unit(x, xm) - to_unit(x, xa)), abs(to_unit(y, ym) - to_unit(y, ya))))
    return np.array(out)


def test_auto_source_is_the_models_vector_field():
    """The exported user functions hold the model's C right-hand side, the time scaling and the ties as C."""
    space = bs.resolve_space(preset="paper-fig2", sets={"k_ip": math.inf})
    src = auto_source(bs.engine(space), space, Axis("mu", 0.05, 1.0), Axis("Omega", 10.0, 200.0), 0.5, 20.0,
                      time_scale=1e4)
    assert "int func(" in src and "int stpnt(" in src and "brakesqueal_rhs(0.0, y, p, f)" in src
    assert "1800" in src  # N0 = 1800/mu, the preset's tie, as a C expression of PAR(1)
    with pytest.raises(BrakesquealError):
        auto_source(bs.engine(space), space, Axis("mu", 0.05, 1.0), Axis("mu", 10.0, 200.0), 0.5, 20.0)


def test_auto_hopf_curve_matches_paper_fig2():
    """Fig. 2's set with rigid pads in (mu, Omega): every AUTO point within 1e-6 of the box of our curve, the
    Hopf point on the equilibrium branch within 1e-8, and both curves end at the same box edges."""
    _require_auto()
    space = bs.resolve_space(preset="paper-fig2", sets={"k_ip": math.inf})
    x, y = Axis("mu", 0.05, 1.0), Axis("Omega", 10.0, 200.0)
    ac = auto_hopf_curve(bs.engine(space), space, x, y, 0.5, 20.0)
    assert len(ac.x) >= 30
    exact = bs.crossings(space.with_values({"mu": 0.5}), y).crossings[0][0]
    assert ac.hopf_start[1] == pytest.approx(exact, rel=1e-8)
    d = _distances(space, x, y, ac)
    assert d.max() <= CURVE_TOL, d.max()
    (ours,) = hopf_curves(bs.engine(space), space, x, y, lyapunov=False)
    ends_auto = sorted([(ac.x[0], ac.y[0]), (ac.x[-1], ac.y[-1])])
    ends_ours = sorted([(ours.points[0].x, ours.points[0].y), (ours.points[-1].x, ours.points[-1].y)])
    for (xa, ya), (xo, yo) in zip(ends_auto, ends_ours):
        assert abs(to_unit(x, xa) - to_unit(x, xo)) <= CURVE_TOL and abs(to_unit(y, ya) - to_unit(y, yo)) <= CURVE_TOL
    assert not [s for s in ac.special if s[0] in ("GH", "BT", "ZH", "HH")]  # none, as ours


@pytest.mark.slow
def test_auto_hopf_curve_and_generalised_hopf_point_match_fig3():
    """Fig. 3's set (mu2 = 0.5) in (mu1, Omega) on a log axis: the curve point by point, and AUTO's GH point
    against ours."""
    _require_auto()
    space = bs.resolve_space(preset="paper-fig3", sets={"k_ip": math.inf, "mu2": 0.5})
    x, y = Axis("mu1", 0.0, 1.0), Axis("Omega", 10.0, 20000.0, log=True)
    ac = auto_hopf_curve(bs.engine(space), space, x, y, 0.5, 12.0)
    d = _distances(space, x, y, ac)
    assert d.max() <= CURVE_TOL, d.max()
    (ours,) = hopf_curves(bs.engine(space), space, x, y)
    gh_auto = [(sx, sy) for t, sx, sy in ac.special if t == "GH"]
    gh_ours = [(s.x, s.y) for s in ours.special_points if s.type == "GH"]
    assert len(gh_auto) == 1 and len(gh_ours) == 1
    (xa, ya), (xo, yo) = gh_auto[0], gh_ours[0]
    assert abs(to_unit(x, xa) - to_unit(x, xo)) <= GH_TOL and abs(to_unit(y, ya) - to_unit(y, yo)) <= GH_TOL


def test_auto_missing_is_one_line(monkeypatch, tmp_path):
    """Without AUTO-07p: a one-line message saying what is missing, never a traceback from the build."""
    monkeypatch.setenv("AUTO_DIR", str(tmp_path / "no-auto"))
    why = auto_available()
    assert why is not None and "AUTO-07p is not installed" in why and "\n" not in why
    space = bs.resolve_space(preset="paper-fig2", sets={"k_ip": math.inf})
    with pytest.raises(BrakesquealError, match="AUTO-07p is not installed"):
        auto_hopf_curve(bs.engine(space), space, Axis("mu", 0.05, 1.0), Axis("Omega", 10.0, 200.0), 0.5, 20.0)


@pytest.mark.slow
def test_auto_hopf_curve_matches_a_built_model():
    """The six-dof model (pads with mass, 12 states) in (mu1, Omega): AUTO's Hopf curve within 1e-6 of ours point
    by point.  Its generalised-Hopf point is 2e-4 of the box from ours: AUTO's l1 is a finite difference of third
    derivatives, ours the pads' exact normal form; at our GH point l1 vanishes within its error estimate by both of
    the project's routines (implicit equations and Kuznetsov's projection on the simulated ODE); at AUTO's, the
    exact routine's l1 is well outside its error estimate (the ODE route's finite differences cannot tell)."""
    from brakesqueal.nonlinear.hopf import first_lyapunov
    from brakesqueal.nonlinear.implicit import exact_lyapunov
    from brakesqueal.nonlinear.models import model_system
    from brakesqueal.region import continue_hopf_curve

    _require_auto()
    space = bs.resolve_space(preset="six-dof")
    eng = bs.engine(space)
    x, y = Axis("mu1", 0.05, 1.0), Axis("Omega", 10.0, 1000.0, log=True)
    x0 = 0.467
    (y0, _), = bs.crossings(space.with_values({"mu1": x0}), Axis("Omega", 20.0, 40.0)).crossings
    ac = auto_hopf_curve(eng, space, x, y, x0, 0.7 * y0)
    d = _distances(space, x, y, ac)
    assert len(ac.x) >= 30 and d.max() <= CURVE_TOL, d.max()
    ours = continue_hopf_curve(eng, space, x, y, x0, y0)
    (g,) = [s for s in ours.special_points if s.type == "GH"]
    (ga,) = [(sx, sy) for t, sx, sy in ac.special if t == "GH"]
    assert abs(to_unit(x, ga[0]) - to_unit(x, g.x)) <= 1e-3 and abs(to_unit(y, ga[1]) - to_unit(y, g.y)) <= 1e-3

    def both(mu1: float, omega: float) -> tuple[tuple[float, float], tuple[float, float]]:
        s = space.with_values({"mu1": mu1})
        h = exact_lyapunov(eng, s, "Omega", omega).hopf
        sysm = model_system(eng, s, "Omega")
        y_eq = sysm.simulation_model.silent(s.resolve({"Omega": h.p0})).y  # type: ignore[attr-defined]
        f = first_lyapunov(sysm, y_eq, h.p0, omega=h.omega0)
        return (h.l1, h.l1_error), (f.l1, f.l1_error)

    for l1, err in both(g.x, g.y):
        assert abs(l1) <= 3 * err
    (l1, err), _ode = both(*ga)
    assert abs(l1) > 10 * err
