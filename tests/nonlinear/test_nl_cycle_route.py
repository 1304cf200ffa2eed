"""Which route computes limit cycles (``cycle_route``, ``cycles --pads``): the pads' true rates by default.

The rule is checked against the model data written out here (a massless pad, Coulomb law, no damper, finite
``k_ip``), on every built-in model and preset; the CLI's default against the two routes run explicitly; the
harmonic-balance branch's folds against shooting's located fold on the same (bilateral, exact) equations.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from brakesqueal import Axis
from brakesqueal.cli import main
from brakesqueal.errors import ParameterError
from brakesqueal.model import MODELS, get_model
from brakesqueal.model.options import damped_pads, regularised_pads
from brakesqueal.model.parameters import ParameterSpace
from brakesqueal.nonlinear.harmonic import turning_points
from brakesqueal import harmonic_branch
from brakesqueal.nonlinear.models import cycle_route, soft_quasi_static_pads
from brakesqueal import squeal_branch

FIG3 = ["--preset", "paper-fig3", "--set", "mu1=0.5", "--set", "mu2=0.5", "--along", "Omega=30:40"]


def _soft_by_hand(space: ParameterSpace) -> set[str]:
    """Massless pads (no tangential DOF) with the Coulomb law, no tangential damper and a finite k_ip."""
    params = space.resolve({})
    out = set()
    for pad in params.model.pads:
        if "tangential" in pad.dofs or pad.friction.law != "coulomb":
            continue
        d = pad.d_ip
        if d is not None and (float(params[d]) if isinstance(d, str) else float(d)) != 0.0:
            continue
        k = float(params[pad.k_ip]) if isinstance(pad.k_ip, str) else float(pad.k_ip)
        if not math.isinf(k):
            out.add(pad.name)
    return out


@pytest.mark.parametrize("name", sorted(MODELS))
def test_the_route_follows_the_pads_of_every_built_in_model(name):
    spec = get_model(name)
    names = spec.preset_names()
    assert names  # every built-in model has presets
    for preset in names:
        space = ParameterSpace.from_preset(preset)
        soft = _soft_by_hand(space)
        assert set(soft_quasi_static_pads(space)) == soft, preset
        assert cycle_route(space) == ("harmonic balance" if soft else "shooting")
        assert cycle_route(space, pads="quasi-static") == "shooting"
        assert cycle_route(space, pads="exact") == "harmonic balance"
        if soft:
            with pytest.raises(ParameterError, match="--pad-damping D.*--pads quasi-static"):
                cycle_route(space, contact="unilateral")
        else:
            assert cycle_route(space, contact="unilateral") == "shooting"


def test_pad_options_and_paths_decide_the_route():
    fig3 = ParameterSpace.from_preset("paper-fig3")  # k_ip = 1e8: soft
    assert soft_quasi_static_pads(fig3) == ("1", "2")
    rigid = ParameterSpace.from_preset("paper-fig3", {"k_ip": math.inf})
    assert soft_quasi_static_pads(rigid) == () and cycle_route(rigid, contact="unilateral") == "shooting"
    # a path in k_ip makes rigid pads soft on it
    assert cycle_route(rigid, Axis("k_ip", 1e5, 1e10, 2, True)) == "harmonic balance"
    # a damper or a rising law keeps the rates in the simulated equations: shooting, also through lift-off
    for kept in (damped_pads(fig3, 10.0), regularised_pads(fig3, 1e-4)):
        assert soft_quasi_static_pads(kept) == ()
        assert cycle_route(kept, contact="unilateral") == "shooting"
    with pytest.raises(ParameterError, match="bilateral"):
        cycle_route(fig3, contact="unilateral", pads="exact")
    for bad in ({"pads": "exactly"}, {"contact": "sometimes"}):
        with pytest.raises(ParameterError, match="pads|contact"):
            cycle_route(fig3, **bad)


@pytest.mark.slow
def test_cycles_default_is_the_exact_pads_route(capsys):
    assert main(["cycles", *FIG3, "--max-points", "6", "--format", "json"]) == 0
    auto = json.loads(capsys.readouterr().out)
    assert main(["cycles", *FIG3, "--max-points", "6", "--format", "json", "--exact-pads"]) == 0
    exact = json.loads(capsys.readouterr().out)
    assert auto == exact and auto["method"].startswith("harmonic balance")
    assert main(["cycles", *FIG3, "--max-points", "6", "--format", "json", "--pads", "quasi-static"]) == 0
    qs = json.loads(capsys.readouterr().out)
    # the two routes: same exact Hopf point; the quasi-static pads' branch starts from its own normal form
    assert qs["hopf"]["hopf"]["p0"] == pytest.approx(auto["hopf"]["p0"], rel=1e-9)
    assert qs["hopf"]["hopf_simulated"]["l1"] != pytest.approx(auto["hopf"]["l1"], rel=1e-3)
    # the summary has the same keys on both routes
    assert set(auto["summary"]) == set(qs["summary"])
    assert auto["summary"]["onset"] == auto["hopf"]["p0"] and auto["summary"]["contact"] == "bilateral"
    assert auto["summary"]["contact_loss"] == auto["contact_loss"]
    rows = auto["summary"]["table"]
    assert [r["p"] for r in rows] == [p["p"] for p in auto["points"]]
    for r, pt in zip(rows, auto["points"]):
        assert r["F_n_min"] == pt["F_n_min"] and r["stable"] == pt["stable"]
        assert all(hi >= lo for hi, lo in zip(r["F_n_max"], r["F_n_min"]))
    # every orbit before the located contact loss is pressed all period: duty 1; stable ones span the range
    assert all(r["duty_cycle"] == [1.0, 1.0] for r in rows)
    st = [r["p"] for r in rows if r["stable"]]
    assert auto["summary"]["squeal_range"] == [min(st), max(st)]
    # the text says which route and prints the summary
    assert main(["cycles", *FIG3, "--max-points", "6"]) == 0
    text = capsys.readouterr().out
    assert "harmonic balance" in text and "squeal onset (linear)" in text and "exact pads" in text


def test_cycles_unilateral_asks_for_the_pads_treatment(capsys):
    assert main(["cycles", *FIG3, "--contact", "unilateral"]) == 2
    err = capsys.readouterr().err
    assert "--pad-damping D" in err and "--pads quasi-static" in err and "Traceback" not in err
    assert main(["cycles", *FIG3, "--pads", "sometimes"]) == 2
    assert "--pads" in capsys.readouterr().err
    assert main(["cycles", *FIG3, "--exact-pads", "--pads", "quasi-static"]) == 2
    assert main(["cycles", *FIG3, "--pads", "exact", "--contact", "unilateral"]) == 2
    assert "bilateral" in capsys.readouterr().err


def test_turning_points_locate_a_parabolic_fold():
    rng = np.random.default_rng(7)
    for _ in range(20):
        top, h, c = rng.uniform(-5, 5), rng.uniform(0.01, 1.0), rng.uniform(-0.5, 0.5)
        s = np.arange(-4, 6) + c  # the vertex anywhere between two samples
        p = top - h * s**2  # a fold (maximum in p) at `top`
        assert turning_points(p) == [pytest.approx(top, rel=1e-12, abs=1e-12)]
        assert turning_points(-p) == [pytest.approx(-top, rel=1e-12, abs=1e-12)]
    assert turning_points(np.linspace(0, 1, 9)) == []
    two = np.concatenate([np.linspace(0, 1, 5), np.linspace(0.9, 0.2, 5), np.linspace(0.25, 0.6, 4)])
    assert len(turning_points(two)) == 2


@pytest.mark.slow
def test_harmonic_balance_folds_agree_with_shooting():
    # six-dof: massive pads, so shooting integrates the exact equations too; the subcritical branch turns at a
    # fold past the contact loss (the bilateral equations continued on both routes)
    space = ParameterSpace.from_preset("six-dof")
    axis = Axis("d_t", 0.1, 1e4, 2, True)
    shot = squeal_branch(space, axis, max_points=200)
    lpc = [sp.p for sp in shot.branch.special if sp.kind == "LPC"]
    assert lpc, shot.branch.message
    hb = harmonic_branch(space, axis, max_points=250, ds_max=1.0, stability=False, stop_at_contact_loss=False)
    p0 = hb.hopf.hopf.p0
    assert hb.contact_loss is not None and p0 < hb.contact_loss < lpc[0]  # recorded on the way
    assert len(hb.folds) >= 1
    # located to the step: within 1 % of the fold's distance from the onset (2e-5 relative measured)
    assert abs(hb.folds[0] - lpc[0]) < 0.01 * abs(lpc[0] - p0), (hb.folds, lpc)
    assert hb.summary.folds == hb.folds and hb.summary.criticality == "subcritical"
    # the fold lies past the contact loss: neither route's summary claims a hysteresis the bilateral model cannot
    # describe (the shooting branch itself has one: unstable cycles turn stable at the fold)
    assert shot.branch.hysteresis_range is not None
    assert shot.summary.hysteresis_range is None and hb.summary.hysteresis_range is None
    # past the contact loss the orbits are not valid: the figure greys them (whatever their stability), as the
    # explorer does, and the summary's table gives them no duty cycle
    valid = hb.valid
    n_bad = valid.count(False)
    assert valid[0] and n_bad > 0 and valid == sorted(valid, reverse=True)
    fig = hb.plot()
    grey = [ln for ax in fig.axes for ln in ax.lines if ln.get_color() == "0.75" and len(ln.get_xdata()) == 2]
    assert len(grey) == 2 * n_bad  # one segment per invalid orbit, in both panels
    assert "contact lost (not valid)" in [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert [r["duty_cycle"][0] is None for r in hb.summary.table] == [not v for v in valid]


def _hill_complex_companion(J, n, m, H, omega):
    """Reference: Hill's pencil in the complex exponential basis, companion form of size 2(n + m)(2H + 1)
    (the formulation harmonic.py used before hill_pencil_eigen), written out here."""
    import scipy.linalg as sl

    N = n + m
    Mt = J.shape[-1]
    th = 2 * np.pi * np.arange(Mt) / Mt
    JQ, JdQ, JddQ = J[:, :n], J[:, n:2 * n], J[:, 2 * n:3 * n]
    JL, JdL = J[:, 3 * n:3 * n + m], J[:, 3 * n + m:]
    B0 = np.concatenate([JQ, JL], axis=1)
    B1 = np.concatenate([JdQ, JdL], axis=1)
    B2 = np.concatenate([JddQ, np.zeros_like(JL)], axis=1)
    ks = np.arange(-H, H + 1)
    Ec = np.exp(1j * np.outer(th, ks))
    Pc = Ec.conj().T / Mt
    Dk = 1j * omega * ks

    def op(B, w):
        return np.einsum("at,ikt,tb,b->iakb", Pc, B.astype(complex), Ec, w).reshape(N * ks.size, N * ks.size)

    one = np.ones(ks.size)
    A0 = op(B0, one) + op(B1, Dk) + op(B2, Dk * Dk)
    A1 = op(B1, one) + 2 * op(B2, Dk)
    A2 = op(B2, one)
    S = N * ks.size
    L = np.block([[np.zeros((S, S)), np.eye(S)], [-A0, -A1]])
    R = np.block([[np.eye(S), np.zeros((S, S))], [np.zeros((S, S)), A2]])
    lam, V = sl.eig(L, R)
    return lam, V[:S].reshape(N, ks.size, -1)


@pytest.mark.parametrize("seed", range(6))
def test_hill_pencil_equals_the_complex_companion_form(seed):
    from brakesqueal.nonlinear.harmonic import hill_pencil_eigen

    rng = np.random.default_rng(seed)
    n, m, H = int(rng.integers(1, 4)), int(rng.integers(0, 3)), int(rng.integers(2, 9))
    omega = float(rng.uniform(0.5, 5.0))
    Mt = 4 * H + 4
    th = 2 * np.pi * np.arange(Mt) / Mt
    N = n + m

    def periodic(rows, cols, size):  # smooth periodic coefficients: a few harmonics
        out = rng.normal(scale=size, size=(rows, cols, 1)) * np.ones(Mt)
        for k in (1, 2):
            out = out + 0.2 * size * (rng.normal(size=(rows, cols, 1)) * np.cos(k * th)
                                      + rng.normal(size=(rows, cols, 1)) * np.sin(k * th))
        return out

    J = np.zeros((N, 3 * n + 2 * m, Mt))
    J[:, :n] = periodic(N, n, 3.0)
    J[:, n:2 * n] = periodic(N, n, 0.5)
    J[:n, 2 * n:3 * n] = np.eye(n)[:, :, None] + 0.1 * periodic(n, n, 1.0)  # mass on the coordinates' rows
    J[:, 3 * n:3 * n + m] = periodic(N, m, 1.0)
    J[n:, 3 * n + m:] = 2.0 * np.eye(m)[:, :, None] + 0.1 * periodic(m, m, 1.0)  # the pads' rates
    lam, V = hill_pencil_eigen(J, n, m, H, omega)
    ref, Vref = _hill_complex_companion(J, n, m, H, omega)
    fin, rfin = lam[np.isfinite(lam)], ref[np.isfinite(ref)]
    big = 1e6 * omega * H
    fin, rfin = fin[np.abs(fin) < big], rfin[np.abs(rfin) < big]
    assert fin.size == rfin.size == (2 * n + m) * (2 * H + 1)
    scale = max(1.0, float(np.abs(rfin).max()))
    for z in rfin:  # every reference eigenvalue once, to rounding
        j = int(np.argmin(np.abs(fin - z)))
        assert abs(fin[j] - z) < 1e-8 * scale, (z, fin[j])
        fin = np.delete(fin, j)
    for j in np.flatnonzero(np.isfinite(lam) & (np.abs(lam) < 0.5 * H * omega))[:5]:
        i = int(np.argmin(np.abs(ref - lam[j])))
        a, b = V[:, :, j].ravel(), Vref[:, :, i].ravel()
        if np.min(np.abs(np.delete(ref, i) - ref[i])) > 1e-3 * scale:  # a simple eigenvalue
            assert abs(np.vdot(a, b)) / (np.linalg.norm(a) * np.linalg.norm(b)) > 1 - 1e-8


@pytest.mark.slow
def test_a_nonlinear_simulation_says_when_its_pads_are_quasi_static():
    from brakesqueal import simulate

    def run(over, **kw):
        space = ParameterSpace.from_preset("paper-fig3", {"mu1": 0.5, "mu2": 0.5, "Omega": 60.0, **over})
        return space, simulate(space.resolve({}), 0.3, events="continue", **kw)

    space, tr = run({}, perturbation=[3e-3, 0.0])
    assert tr.summary.regime == "nonlinear"
    # the pads the route rule names (cycle_route) are those the run names
    assert tr.soft_quasi_static_pads == soft_quasi_static_pads(space) == ("1", "2")
    assert any("quasi-static" in w and "--pad-damping" in w for w in tr.summary.warnings)
    _, small = run({}, perturbation=[1e-6, 0.0])  # the linear regime: the quasi-static pad is exact there
    assert small.summary.regime == "linear" and not any("quasi-static" in w for w in small.summary.warnings)
    _, rigid = run({"k_ip": math.inf}, perturbation=[3e-3, 0.0])
    assert rigid.soft_quasi_static_pads == () and not any("quasi-static" in w for w in rigid.summary.warnings)
    damped = damped_pads(ParameterSpace.from_preset("paper-fig3", {"mu1": 0.5, "mu2": 0.5, "Omega": 60.0}), 10.0)
    tr_d = simulate(damped.resolve({}), 0.05, perturbation=[3e-3, 0.0], events="continue")
    assert tr_d.soft_quasi_static_pads == ()


def test_both_routes_share_the_summary_keys_of_the_json(capsys):
    args = ["cycles", *FIG3, "--max-points", "6", "--format", "json"]
    assert main(args) == 0
    hb = json.loads(capsys.readouterr().out)
    assert main([*args, "--pads", "quasi-static"]) == 0
    shot = json.loads(capsys.readouterr().out)
    common = {"status", "message", "contact_loss", "contact", "summary", "special_points", "hysteresis_range",
              "in_contact_up_to", "amplitude_at_last_contact_point", "frequency_hz_at_last_contact_point"}
    assert common <= set(hb) and common <= set(shot)
    assert (hb["route"], shot["route"]) == ("harmonic balance", "shooting")
    assert hb["n_points"] == len(hb["points"]) and shot["n_points"] == shot["points"]
    assert hb["special_points"][0] == {"kind": "H", "p": hb["hopf"]["p0"]}
    # the last orbit with every pad pressed: the last point (the branch ends at a located contact loss, if any)
    assert all(min(pt["F_n_min"]) > 0 for pt in hb["points"]) and hb["in_contact_up_to"] == hb["points"][-1]["p"]
    last = hb["points"][-1]
    assert hb["amplitude_at_last_contact_point"] == last["amplitude"]
    assert hb["frequency_hz_at_last_contact_point"] == last["frequency_hz"]


def _synthetic_branch(ps, stable, fmin, criticality="subcritical"):
    """A HarmonicBranch assembled by hand: only the fields the summary reads carry meaning."""
    from types import SimpleNamespace

    from brakesqueal.nonlinear.harmonic import HarmonicBranch, HarmonicPoint

    pts = tuple(HarmonicPoint(p, 10.0, 10.0 / (2 * np.pi), {"q1": 1e-3 * (i + 1)}, 1e-3 * (i + 1), (f, f), 1.0,
                              1e-12, 1e-9, 6, np.zeros((1, 13)), None, st, None, None, (3000.0, 3000.0),
                              verdict="undecided" if st is None else "stable" if st else "unstable")
                for i, (p, st, f) in enumerate(zip(ps, stable, fmin)))
    h = SimpleNamespace(p0=0.0, criticality=criticality, side=1, omega0=10.0, frequency0_hz=1.6, l1=1.0,
                        l1_error=0.0)
    return HarmonicBranch("p", SimpleNamespace(hopf=h), pts, "max_points", "", None, None, ("q1",), ("1", "2"))


def test_the_summary_reads_folds_verdicts_and_contact_like_shooting():
    ps = [0.1, 0.2, 0.3, 0.34, 0.3, 0.2]
    # unstable cycles, no verdict around the fold (an exponent crossing 0), then stable ones: hysteresis
    b = _synthetic_branch(ps, [False, False, None, None, None, True], [2000.0] * 6)
    s = b.summary
    assert len(b.folds) == 1 and 0.34 <= b.folds[0] <= 0.36
    assert s.hysteresis_range == (0.0, b.folds[0]) and s.squeal_range == (0.2, 0.2)
    # the pads lift off before the first verdict after the fold: the bilateral branch is not valid there
    lifted = _synthetic_branch(ps, [False, False, None, None, None, True], [2000.0, 1000.0, 500.0, -1.0, 5.0, 9.0])
    sl = lifted.summary
    assert sl.hysteresis_range is None and sl.squeal_range is None
    # the first run of pressed orbits only: the orbits after the first lift-off are not valid even if F_n > 0
    assert [r["duty_cycle"][0] for r in sl.table] == [1.0, 1.0, 1.0, None, None, None]
    assert lifted.to_dict()["in_contact_up_to"] == 0.3
    # a branch without verdicts says so rather than "no stable limit cycle"
    none = _synthetic_branch(ps[:3], [None] * 3, [2000.0] * 3, "supercritical")
    # an orbit flagged stable whose verdict is undecided (Hill and the monodromy disagree) bounds no squeal range
    from dataclasses import replace

    und = replace(b, points=tuple(replace(pt, verdict="undecided") if pt.stable else pt for pt in b.points))
    assert und.summary.squeal_range is None and "stability undecided" in und.summary.text(rows=0)
    text = none.summary.text(rows=0)
    assert "stability not computed" in text and "no stable limit cycle" not in text
    assert none.to_dict()["route"] == "harmonic balance" and none.to_dict()["n_points"] == 3


def test_quasi_static_pads_do_not_combine_with_kept_rates(capsys):
    assert main(["cycles", *FIG3, "--pads", "quasi-static", "--pad-damping", "10"]) == 2
    assert "--pads quasi-static" in capsys.readouterr().err


def test_the_bifurcation_diagram_marks_the_folds():
    import matplotlib

    matplotlib.use("Agg")
    b = _synthetic_branch([0.1, 0.2, 0.3, 0.34, 0.3, 0.2], [False, False, None, None, None, True], [2000.0] * 6)
    fig = b.plot()
    ax = fig.axes[0]
    labels = ax.get_legend_handles_labels()[1]
    assert "fold (LPC)" in labels and "Hopf point" in labels
    (line,) = [ln for ln in ax.lines if ln.get_label() == "fold (LPC)"]
    assert line.get_xdata()[0] == pytest.approx(b.folds[0]) and line.get_ydata()[0] == pytest.approx(4e-3)
    plain = _synthetic_branch([0.1, 0.2, 0.3], [True] * 3, [2000.0] * 3, "supercritical")
    assert "fold (LPC)" not in plain.plot().axes[0].get_legend_handles_labels()[1]
