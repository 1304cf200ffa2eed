"""l1 along a Hopf curve by the direct route (issue 28: a 200-point curve with l1 in seconds).

``continue_hopf_curve`` computes ``l1`` at every point with
:func:`brakesqueal.nonlinear.implicit.lyapunov_at_hopf`: the corrected point, its eigenvalue and the curve's own
``d lambda / dp`` passed in (no re-refinement), double-precision eigenvalues where their error bounds decide every
check.  Checked here against the full :func:`~brakesqueal.nonlinear.implicit.exact_lyapunov` at the same points and
against values recorded with the previous code.

The previous values (``PREVIOUS_*``) were recorded by running the code of commit 22b646f (``region/curves.py``,
``nonlinear/implicit.py`` as they were before this change) on the same calls: ``hopf_curves`` of the sets below,
``(GH.x, GH.y)`` of their special points.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import brakesqueal as bs
from brakesqueal.analysis.maps import Axis
from brakesqueal.nonlinear import implicit
from brakesqueal.nonlinear.implicit import exact_lyapunov, lyapunov_at_hopf
from brakesqueal.region import curves, hopf_curves
from brakesqueal.simulation import simulation_model

FIG3 = {"k_ip": math.inf, "mu2": 0.5}
X3, Y3 = Axis("mu1", 0.0, 1.0), Axis("Omega", 10.0, 20000.0, log=True)
X2, Y2 = Axis("mu", 0.05, 1.0), Axis("Omega", 10.0, 200.0)
#: The generalised-Hopf point of ``hopf_curves`` on Fig. 3's set by the previous code (commit 22b646f).
PREVIOUS_GH_FIG3 = (0.23870583682647745, 3098.23467844861)
#: ``exact_lyapunov`` (public route) on paper-fig2, k_ip = inf, mu = 0.6 at its crossing in Omega by the previous
#: code: (p0, l1, l1_error).  Its chord refinement is unchanged and the shared finite-difference evaluations of the
#: normal form give the same numbers (bit for bit on the machine that recorded them).
PREVIOUS_EXACT_FIG2 = (29.77747785234232, -2.1211870824508444e-09, 1.3152664520767846e-15)
#: Largest distance (unit box) of the GH point from the previous code's.  The previous code itself moves it by
#: up to 7.7e-9 when the curve is seeded elsewhere on it (mu1 = 0.3, 0.5, 0.7): the finite differences' rounding
#: in l1 (about 1e-8 of its terms, far inside l1_error) decides the last digits of the secant.  The point's
#: resolution by l1_error itself is 5e-5 of the box.
GH_TOL = 5e-8


def _unit(ax: Axis, v: float) -> float:
    if ax.log:
        return (math.log10(v) - math.log10(ax.start)) / (math.log10(ax.stop) - math.log10(ax.start))
    return (v - ax.start) / (ax.stop - ax.start)


@pytest.fixture(scope="module")
def fig3():
    space = bs.resolve_space(preset="paper-fig3", sets=FIG3)
    eng = bs.engine(space)
    (curve,) = hopf_curves(eng, space, X3, Y3)
    return space, eng, curve


def _full(eng, space, x: Axis, y: Axis, p):
    """The previous per-point route: the full exact_lyapunov along Omega through the point."""
    return exact_lyapunov(eng, space.with_values({x.name: p.x}), y.name, p.y, omega=p.omega).hopf


def test_curve_l1_equals_the_full_exact_lyapunov_within_its_error(fig3):
    """At random points of Fig. 3's curve (both sides of the GH point) the curve's l1 is the full routine's within
    the reported l1_error (in practice within a few per cent of it), with the same criticality and messages."""
    space, eng, curve = fig3
    fld = curves._Field(eng, space, X3, Y3)
    pts = curve.points
    rng = np.random.default_rng(28)
    sub = [i for i, p in enumerate(pts) if p.criticality == "subcritical"]
    sup = [i for i, p in enumerate(pts) if p.criticality == "supercritical"]
    assert sub and sup
    for k in [*rng.choice(sub, 3, replace=False), *rng.choice(sup, 3, replace=False)]:
        p = pts[int(k)]
        h = _full(eng, space, X3, Y3, p)
        assert p.l1 is not None and p.l1_error is not None
        assert abs(p.l1 - h.l1) <= h.l1_error, (p, h.l1, h.l1_error)
        assert p.l1_error == pytest.approx(h.l1_error, rel=0.5)
        assert p.criticality == h.criticality and p.message == "; ".join(h.warnings)
        # the curve's d lambda / dOmega (passed to the normal form) is the full routine's
        u = fld.unit(p.x, p.y)
        dl = curves._dlam(fld, u, fld.track(u, 1j * p.omega), 1)
        assert dl is not None and abs(dl - h.dlambda_dp) <= 1e-6 * abs(h.dlambda_dp), (dl, h.dlambda_dp)


def test_generalised_hopf_point_where_the_previous_code_put_it(fig3):
    space, eng, curve = fig3
    (g,) = [s for s in curve.special_points if s.type == "GH"]
    d = max(abs(_unit(X3, g.x) - _unit(X3, PREVIOUS_GH_FIG3[0])), abs(_unit(Y3, g.y) - _unit(Y3, PREVIOUS_GH_FIG3[1])))
    assert d <= GH_TOL, d


def test_direct_route_at_a_point_on_the_boundary_is_the_full_one():
    """``lyapunov_at_hopf`` at a crossing (x fixed, along Omega) against ``exact_lyapunov`` started there: the same
    l1 within l1_error, the same eigenvalue, criticality and side; the eigenvalues it lists (double precision,
    decided by their bounds) are the extended-precision ones to 1e-12."""
    space = bs.resolve_space(preset="paper-fig2", sets={"k_ip": math.inf})
    eng = bs.engine(space)
    sub = space.with_values({"mu": 0.6})
    (w, _), = bs.crossings(sub, Y2).crossings
    full = exact_lyapunov(eng, sub, "Omega", w).hopf
    fast = lyapunov_at_hopf(eng, sub, "Omega", full.p0, full.eigenvalue, full.dlambda_dp)
    assert abs(fast.l1 - full.l1) <= full.l1_error
    assert fast.eigenvalue == pytest.approx(full.eigenvalue, rel=1e-12)
    assert fast.criticality == full.criticality and fast.side == full.side
    assert fast.eigenvalues.size == full.eigenvalues.size
    for z in full.eigenvalues:
        assert np.min(np.abs(fast.eigenvalues - z)) <= 1e-12 * abs(z)
    assert np.all(np.isnan(fast.dx0_dp))


def test_exact_lyapunov_as_the_previous_code():
    space = bs.resolve_space(preset="paper-fig2", sets={"k_ip": math.inf})
    sub = space.with_values({"mu": 0.6})
    (w, _), = bs.crossings(sub, Y2).crossings
    h = exact_lyapunov(bs.engine(space), sub, "Omega", w).hopf
    p0, l1, err = PREVIOUS_EXACT_FIG2
    assert h.p0 == pytest.approx(p0, rel=1e-11) and h.l1_error == pytest.approx(err, rel=0.1)
    assert abs(h.l1 - l1) <= err and np.all(np.isfinite(h.dx0_dp))


@pytest.mark.parametrize("bad", [{"p": math.nan}, {"eigenvalue": complex(math.inf, 1.0)}, {"dlambda_dp": math.nan},
                                 {"name": "Omgea"}])
def test_direct_route_bad_input_is_one_line(bad):
    from brakesqueal.errors import ParameterError

    space = bs.resolve_space(preset="paper-fig2", sets={"k_ip": math.inf})
    args = {"name": "Omega", "p": 30.0, "eigenvalue": 1e4j, "dlambda_dp": 0.03 + 0.7j, **bad}
    with pytest.raises(ParameterError) as exc:
        lyapunov_at_hopf(bs.engine(space), space, args.pop("name"), args.pop("p"), args.pop("eigenvalue"),
                         args.pop("dlambda_dp"))
    assert "\n" not in str(exc.value)


def test_direct_route_refines_a_point_off_the_boundary():
    """Started 1e-6 off the crossing (|Re lambda| far above 1e-12 |lambda|) it runs exact_lyapunov's chord
    iterations with the given derivative and lands on the same Hopf point."""
    space = bs.resolve_space(preset="paper-fig2", sets={"k_ip": math.inf})
    eng = bs.engine(space)
    sub = space.with_values({"mu": 0.6})
    (w, _), = bs.crossings(sub, Y2).crossings
    full = exact_lyapunov(eng, sub, "Omega", w).hopf
    fast = lyapunov_at_hopf(eng, sub, "Omega", full.p0 * (1 + 1e-6), full.eigenvalue, full.dlambda_dp)
    assert fast.p0 == pytest.approx(full.p0, rel=1e-11)
    assert abs(fast.l1 - full.l1) <= full.l1_error


def _point(space, name: str, value: float, omega: float):
    sim = simulation_model(bs.engine(space))
    pt = implicit._Point(space, sim, name, value)
    return pt, implicit._track(pt.eigenvalues(), complex(0.0, omega))


def _decisions(lams: np.ndarray, lam: complex) -> tuple[bool, int, int]:
    """What the normal form reads from the eigenvalues: a zero one, the others, those on the axis."""
    a = abs(lam)
    others = lams[(np.abs(lams - lam) > 1e-9 * a) & (np.abs(lams - np.conj(lam)) > 1e-9 * a)]
    return bool(np.min(np.abs(lams)) <= 1e-12 * a), others.size, int(np.sum(np.abs(others.real) <= 1e-8 * a))


def test_double_precision_eigenvalues_decide_like_the_extended_ones_on_the_curve(fig3):
    """On Fig. 3's curve (pads eliminated, 4 states) the double-precision list is taken, is the extended one to
    1e-12 and makes the same decisions."""
    space, _eng, curve = fig3
    for p in curve.points[::9]:
        pt, lam = _point(space.with_values({"mu1": p.x}), "Omega", p.y, p.omega)
        got, ref = implicit._checked_eigenvalues(pt, lam), pt.lm.eigenvalues
        assert got is not ref and got.size == ref.size
        for z in ref:
            assert np.min(np.abs(got - z)) <= 1e-12 * abs(z)
        assert _decisions(got, lam) == _decisions(ref, lam)


@pytest.mark.parametrize("seed", range(3))
def test_extended_eigenvalues_where_a_huge_pad_mode_spoils_double_precision(seed):
    """At a tilted silent motion the massless pads keep their own state (descriptor, pad modes 1e12..1e17 times
    the slow ones): double precision is not resolved there and the extended-precision list is used, as by
    exact_lyapunov."""
    rng = np.random.default_rng(seed)
    values = {"mu2": float(rng.uniform(0.05, 0.45)), "k_ip1": float(10 ** rng.uniform(6, 11)),
              "k_ip2": float(10 ** rng.uniform(6, 11))}
    space = bs.resolve_space(preset="paper").with_values(values)
    pt, lam = _point(space, "Omega", 50.0, 1e4)
    assert pt.lm.pad_states and not pt.lm.silent.trivial
    got = implicit._checked_eigenvalues(pt, lam)
    assert got is pt.lm.eigenvalues


@pytest.mark.slow
def test_six_dof_curve_l1_equals_the_full_exact_lyapunov():
    """The six-dof model (pads with mass, 12 states) in (mu1, Omega): at points of its Hopf curve the curve's l1
    is the full routine's within l1_error."""
    from brakesqueal.region import continue_hopf_curve

    space = bs.resolve_space(preset="six-dof")
    eng = bs.engine(space)
    x, y = Axis("mu1", 0.05, 1.0), Axis("Omega", 10.0, 1000.0, log=True)
    (y0, _), = bs.crossings(space.with_values({"mu1": 0.467}), Axis("Omega", 20.0, 40.0)).crossings
    curve = continue_hopf_curve(eng, space, x, y, 0.467, y0, max_points=4)
    for p in curve.points[::2]:
        h = _full(eng, space, x, y, p)
        assert p.l1 is not None and abs(p.l1 - h.l1) <= h.l1_error, (p, h.l1, h.l1_error)
        assert p.criticality == h.criticality
