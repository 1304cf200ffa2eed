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
    assert "int func(" in src and "int stpnt(" in src and "brakesqueal_rhs(0.0, y, p, dy)" in src
    assert "1800" in src  # N0 = 1800/mu, the preset's tie, as a C expression of PAR(1)
    assert "typedef double bsq_real" in src and "long double" not in src
    with pytest.raises(BrakesquealError):
        auto_source(bs.engine(space), space, Axis("mu", 0.05, 1.0), Axis("mu", 10.0, 200.0), 0.5, 20.0)
    # extended precision: the exported model's arithmetic in long double, the scale on the states
    ld = auto_source(bs.engine(space), space, Axis("mu", 0.05, 1.0), Axis("Omega", 10.0, 200.0), 0.5, 20.0,
                     time_scale=1e4, scale=0.5, precision="long double")
    assert "#define double long double" in ld and "typedef long double bsq_real" in ld
    assert "uscale[4] = {0.5, 0.5, 5000.0, 5000.0}" in ld
    for bad in ({"precision": "quad"}, {"scale": 0.0}):
        with pytest.raises(BrakesquealError, match=next(iter(bad))):
            auto_source(bs.engine(space), space, Axis("mu", 0.05, 1.0), Axis("Omega", 10.0, 200.0), 0.5, 20.0,
                        **bad)


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
    by point, and its generalised-Hopf point within GH_TOL of ours, with the model exported in extended precision
    and its states scaled by 0.03 (``scale``, ``precision`` of auto_source); at our GH point l1 vanishes within its
    error estimate by both of the project's routines (implicit equations and Kuznetsov's projection on the
    simulated ODE).

    With the default export AUTO's GH point is 2.3e-4 of the box off ours: AUTO's l1 takes third derivatives by
    finite differences with a fixed step (1.2e-4 along the unit eigenvector, its units), not small against the
    friction's nonlinearity (the sliding speed Omega R, Omega ~ 37 rad/s, while the rates are scaled by the squeal
    frequency W ~ 1e4 rad/s).  Measured (issue 28): scaling every state by 1, 0.3, 0.1, 0.03, 0.01 moves AUTO's GH
    in mu1 by -2.3e-4, -2.1e-5, -2.2e-6, -8.9e-7, +7.0e-6 of the box from ours in extended precision (the error
    falls as the square of the scale until the rounding of the large, cancelling forces takes over), by -2.3e-4,
    -1.0e-5, +3.6e-5, +4.5e-4, -8.5e-3 in double precision (rounding takes over at once); an accurate Jacobian
    (JAC = 1) changes nothing.  So AUTO converges to our point."""
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
    ac = auto_hopf_curve(eng, space, x, y, x0, 0.7 * y0, scale=0.03, precision="long double")
    d = _distances(space, x, y, ac)
    assert len(ac.x) >= 30 and d.max() <= CURVE_TOL, d.max()
    ours = continue_hopf_curve(eng, space, x, y, x0, y0)
    (g,) = [s for s in ours.special_points if s.type == "GH"]
    (ga,) = [(sx, sy) for t, sx, sy in ac.special if t == "GH"]
    assert abs(to_unit(x, ga[0]) - to_unit(x, g.x)) <= GH_TOL and abs(to_unit(y, ga[1]) - to_unit(y, g.y)) <= GH_TOL

    def both(mu1: float, omega: float) -> tuple[tuple[float, float], tuple[float, float]]:
        s = space.with_values({"mu1": mu1})
        h = exact_lyapunov(eng, s, "Omega", omega).hopf
        sysm = model_system(eng, s, "Omega")
        y_eq = sysm.simulation_model.silent(s.resolve({"Omega": h.p0})).y  # type: ignore[attr-defined]
        f = first_lyapunov(sysm, y_eq, h.p0, omega=h.omega0)
        return (h.l1, h.l1_error), (f.l1, f.l1_error)

    for l1, err in both(g.x, g.y):
        assert abs(l1) <= 3 * err


def test_export_to_auto_writes_the_user_functions_the_comparisons_run(tmp_path, capsys):
    """``brakesqueal export --to auto``: the file AUTO-07p's comparisons build, from the parameters' current
    values; axes missing, out of range, or given to another target: one line, exit 2."""
    from brakesqueal.cli import main

    out = tmp_path / "paper.c"
    rc = main(["export", "--to", "auto", "--preset", "paper-fig2", "--set", "k_ip=inf", "--x", "mu=0.05:1",
               "--y", "Omega=10:200", "--out", str(out)])
    assert rc == 0, capsys.readouterr().err
    space = bs.resolve_space(preset="paper-fig2", sets={"k_ip": math.inf})
    assert out.read_text() == auto_source(bs.engine(space), space, Axis("mu", 0.05, 1.0), Axis("Omega", 10.0, 200.0),
                                          0.5, space.value("Omega"))
    capsys.readouterr()
    for args, word in ((["--x", "mu=0.05:1"], "--y"), (["--x", "mu=0.6:1", "--y", "Omega=10:200"], "[0.6, 1]"),
                       (["--what", "linear", "--x", "mu=0.05:1", "--y", "Omega=10:200"], "--what")):
        assert main(["export", "--to", "auto", "--preset", "paper-fig2", *args, "--out", str(tmp_path / "x.c")]) == 2
        err = capsys.readouterr().err
        assert word in err and "Traceback" not in err and err.count("\n") == 1
    assert main(["export", "--to", "c", "--preset", "paper-fig2", "--x", "mu=0:1", "--out", str(tmp_path / "m.c")]) == 2
    assert "--to auto" in capsys.readouterr().err
