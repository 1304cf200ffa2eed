"""Hopf criticality of the brake models (nonlinear.models): exact Jacobians, Hopf points, cycle prediction.

Independent checks:
* the exact vector-field Jacobian (implicit differentiation of the generated derivatives) against
  central differences of the compiled right-hand side, at random states of every built-in model;
* the refined Hopf point against the exact crossing (roots of the Hurwitz polynomial) and the
  frequency of the linearization there (``scipy.linalg.eigvals``);
* the predicted limit-cycle amplitude ``a_j sqrt(dp)`` (from l1) against periodic orbits of the full
  nonlinear equations found by shooting: the ratio tends to 1 as dp -> 0.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import scipy.linalg

from brakesqueal import linearize
from brakesqueal import Axis
from brakesqueal.cli import main
from brakesqueal.model import MODELS, ParameterSpace
from brakesqueal.nonlinear import find_periodic_orbit
from brakesqueal import hopf_points, model_system
from brakesqueal import simulation_model


@pytest.mark.slow
@pytest.mark.parametrize("name", list(MODELS))
def test_vector_field_jacobian_is_exact(name):
    space = ParameterSpace.from_preset(name)
    params = space.resolve({})
    sim = simulation_model(params.model)
    st = sim.silent(params)
    f, jac = sim.vector_field(params, st)
    np.testing.assert_allclose(jac(st.y), sim.linear_matrix(params)[0], rtol=1e-9, atol=1e-12)
    rng = np.random.default_rng(len(name))
    scale = np.maximum(np.abs(st.y), 1e-3)
    for _ in range(3):
        y = st.y + 1e-4 * rng.standard_normal(st.y.size) * scale
        J = jac(y)
        cols = []
        for i in range(y.size):
            e = np.zeros(y.size)
            e[i] = 1e-7 * scale[i]
            cols.append((f(y + e) - f(y - e)) / (2 * e[i]))
        fd = np.column_stack(cols)
        assert np.max(np.abs(J - fd)) <= 1e-6 * np.max(np.abs(J)), name


@pytest.fixture(scope="module")
def fig3_onset():
    space = ParameterSpace.from_preset("paper-fig3", {"mu1": 0.5, "mu2": 0.5, "k_ip": math.inf})
    pts = hopf_points(space, Axis("Omega", 1.0, 1e3, log=True))
    assert len(pts) == 1
    return space, pts[0]


def test_hopf_point_is_the_exact_crossing(fig3_onset):
    space, hp = fig3_onset
    h = hp.hopf
    assert hp.direction == "destabilizing" and h is not None
    assert h.p0 == pytest.approx(35.601027692919985, rel=1e-9)  # the exact crossing (README, Fig. 3)
    lm = linearize(space.resolve({"Omega": h.p0}))
    n = lm.M.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(lm.M, lm.K), -np.linalg.solve(lm.M, lm.D)]])
    lam = scipy.linalg.eigvals(A)
    top = lam[np.argmax(lam.real)]
    assert abs(top.real) < 1e-9 * abs(top)
    assert h.omega0 == pytest.approx(abs(top.imag), rel=1e-9)
    assert h.criticality == "supercritical" and h.side == 1 and h.l1 < -10 * h.l1_error


def test_predicted_amplitude_matches_periodic_orbits(fig3_onset):
    space, hp = fig3_onset
    h = hp.hopf
    system = model_system(space, "Omega")
    errs = []
    for rel in (1e-2, 1e-3):
        dp = rel * h.p0
        o = find_periodic_orbit(system, h.cycle_guess(h.p0 + dp), tol=1e-8)
        ratio = o.amplitude[:2] / h.amplitude(h.p0 + dp)[:2]
        errs.append(float(np.max(np.abs(ratio - 1))))
        assert o.period == pytest.approx(h.period(h.p0 + dp), rel=10 * rel)
    assert errs[1] < 0.3 * errs[0] and errs[1] < 5e-3, errs


@pytest.mark.parametrize("name,along", [("six-dof", "Omega=1:1e3:log"), ("minimal", "Omega=1:1e4:log"),
                                        ("belt", "slope=0:0.02")])
@pytest.mark.slow
def test_hopf_command_on_built_models(name, along, capsys):
    assert main(["hopf", "--model", name, "--along", along, "--format", "json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["parameter"] == along.split("=")[0]
    for c in d["crossings"]:
        if c["hopf"] is None:
            assert c["message"]
            continue
        h = c["hopf"]
        assert h["criticality"] in ("supercritical", "subcritical", "degenerate")
        assert h["frequency_hz"] == pytest.approx(h["omega0"] / (2 * math.pi))
        assert abs(h["p0"] - c["value"]) <= 1e-12 * abs(h["p0"]) + 1e-300


def test_hopf_text_and_bad_parameter(capsys):
    assert main(["hopf", "--preset", "paper-fig3", "--set", "mu1=0.5", "--set", "mu2=0.5",
                 "--along", "Omega=1:1e3:log"]) == 0
    out = capsys.readouterr().out
    assert "supercritical" in out and "l1 =" in out and "a_j" in out
    assert main(["hopf", "--along", "Omgea=1:10"]) == 2
    assert "did you mean 'Omega'" in capsys.readouterr().err


@pytest.mark.slow
def test_squeal_branch_finds_contact_loss(tmp_path, capsys):
    """The branch's contact loss is where a periodic orbit (shooting, independent of the branch) grazes F_n = 0."""
    from brakesqueal import squeal_branch

    space = ParameterSpace.from_preset("paper-fig3", {"mu1": 0.5, "mu2": 0.5, "k_ip": math.inf})
    b = squeal_branch(space, Axis("Omega", 30.0, 40.0), max_points=25)
    ds = b.data
    assert b.contact_loss is not None and b.hopf.hopf.p0 < b.contact_loss < 37.0  # about 0.5 rad/s past onset
    ok = ds["in_contact"].values
    assert ok[0] and not ok[-1] and np.all(np.diff(ok.astype(int)) <= 0)  # in contact up to a point, then not
    # independent: the orbit at the contact-loss value, by shooting from the nearest branch orbit
    system = model_system(space, "Omega")
    sim = system.simulation_model
    i = int(np.argmin(np.abs(ds["p"].values - b.contact_loss)))
    o = find_periodic_orbit(system, ds["orbit"].values[i][0], period=float(ds["period"].values[i]),
                            p=b.contact_loss, tol=1e-8, n_samples=256)
    params = space.resolve({"Omega": b.contact_loss})
    st = sim.silent(params)
    fmin = min(float(sim.contact_at(params, y, st)[:, 0].min()) for y in o.samples)
    assert abs(fmin) < 0.03 * 3000.0, fmin  # N0 = 3000 N; the branch interpolates linearly between points
    # the command line
    out = tmp_path / "b.nc"
    assert main(["cycles", "--preset", "paper-fig3", "--set", "mu1=0.5", "--set", "mu2=0.5", "--along",
                 "Omega=30:40", "--max-points", "25", "--format", "json", "--out", str(out), "--pads", "quasi-static"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["contact_loss"] and d["hopf"]["hopf"]["criticality"] == "supercritical"
    import xarray as xr

    with xr.open_dataset(out, engine="scipy") as f:
        assert "F_n_min" in f and f.sizes["point"] == d["points"]
        assert "duty_cycle" in f and "tilt_amplitude" in f and "summary" in f.attrs
    # the engineer's summary (issue 14 item 4), checked against quantities computed here
    sm = b.summary
    assert sm is not None and sm.criticality == "supercritical" and sm.onset == b.hopf.hopf.p0
    assert sm.squeal_range is not None and sm.squeal_range[0] == pytest.approx(sm.onset)
    assert sm.squeal_range[1] <= b.contact_loss  # bilateral: no valid squeal beyond the first lift-off
    assert sm.hysteresis_range is None and sm.folds == []  # supercritical, no fold on the bilateral branch
    N0 = 3000.0
    assert sm.table[0]["F_n_max"] == pytest.approx([N0, N0], rel=1e-9)  # the Hopf row: the silent motion
    for i, row in enumerate(sm.table):
        orbit = ds["orbit"].values[i]
        if i > 0:  # first-harmonic tilt amplitude by a DFT of the orbit's samples, here
            X = np.fft.rfft(orbit[:, :2], axis=0)
            assert row["tilt_amplitude"] == pytest.approx(float((2 * np.abs(X[1]) / orbit.shape[0]).max()),
                                                          rel=1e-9)
        params = space.resolve({"Omega": row["p"]})
        F = np.array([sim.contact_at(params, y, sim.silent(params))[:, 0] for y in orbit])
        if np.all(F > 0):
            assert row["duty_cycle"] == [1.0, 1.0] and row["F_n_max"] == pytest.approx(F.max(axis=0), rel=1e-12)
        else:
            assert row["duty_cycle"] == [None, None]
    assert main(["cycles", "--preset", "paper-fig3", "--set", "mu1=0.5", "--set", "mu2=0.5", "--along",
                 "Omega=30:40", "--max-points", "6", "--pads", "quasi-static"]) == 0
    text = capsys.readouterr().out
    assert "squeal onset (linear): Omega = 35.740780" in text and "stable squeal" in text and "duty" in text
    assert main(["cycles", "--along", "Omega=30:40", "--contact", "sometimes"]) == 2


def test_an_undecided_orbit_is_not_counted_in_the_squeal_range():
    """The squeal range spans the orbits certified stable: an interior orbit whose Floquet verdict is undecided
    (a multiplier within the accuracy of the unit circle) bounds it no more, and the text says so; the Hopf
    point (undecided by construction) still bounds it."""
    from dataclasses import replace

    from brakesqueal import squeal_branch
    from brakesqueal.nonlinear.squeal import squeal_summary

    space = ParameterSpace.from_preset("paper-fig3", {"mu1": 0.5, "mu2": 0.5, "k_ip": math.inf})
    b = squeal_branch(space, Axis("Omega", 30.0, 40.0), max_points=12)
    sm = squeal_summary(b)
    assert sm.squeal_range is not None and sm.squeal_range[0] == pytest.approx(sm.onset)
    assert "undecided" not in sm.text(rows=0)
    ds = b.data
    p = ds["p"].values
    located = {int(i) for i in ds["special_index"].values}
    inside = [i for i in range(p.size) if i not in located and p[i] <= sm.squeal_range[1] and ds["stable"].values[i]]
    assert len(inside) >= 3
    cut = inside[1]  # every orbit from the second interior one on: undecided, still flagged stable
    data = ds.copy()
    verdict = data["verdict"].values.astype(object)
    verdict[cut:] = "undecided"
    data["verdict"] = ("point", verdict.astype(str))
    b2 = replace(b, branch=replace(b.branch, data=data))
    sm2 = squeal_summary(b2)
    assert sm2.squeal_range == (pytest.approx(sm.onset), pytest.approx(float(p[inside[0]])))
    assert "stability undecided (not counted in the range)" in sm2.text(rows=0)
