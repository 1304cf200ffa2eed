"""Limit cycles with the exact, unregularised massless Coulomb pads by harmonic balance (nonlinear.harmonic).

Independent references:
* near the Hopf point, the exact normal form of the implicit equations (``exact_lyapunov``: the amplitude law
  ``a_j sqrt(|p - p0|)``, the frequency slope and the radial Floquet exponent ``-2 mu' (p - p0)``);
* the pads regularised by ``mu + S v`` (an explicit ODE; branches by shooting, ``squeal_branch(pad_slope=S)``)
  converge to the harmonic-balance branch of the unregularised model at rate O(S);
* with rigid pads (``k_ip = inf``, the quasi-static pads of the shooting are exact) the harmonic-balance branch
  equals the shooting branch (amplitudes, frequency, Floquet multipliers, located contact loss);
* the orbit satisfies the implicit equations at 997 off-grid times (the compiled model's scalar residuals, the
  series and its derivatives written here), and the truncation error falls as the harmonics increase;
* the exact Jacobian of the harmonic-balance equations against central differences of its residual.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from brakesqueal import Axis
from brakesqueal.cli import main
from brakesqueal.errors import ParameterError
from brakesqueal.model import ParameterSpace
from brakesqueal import harmonic_branch
from brakesqueal import squeal_branch

SOFT = {"mu1": 0.5, "mu2": 0.5, "k_ip1": 1e6, "k_ip2": 1e6}  # Hopf at 64.81 rad/s, 1741 Hz, supercritical


@pytest.fixture(scope="module")
def soft():
    return ParameterSpace.from_preset("paper-fig3", SOFT)


@pytest.fixture(scope="module")
def rigid():
    return ParameterSpace.from_preset("paper-fig3", {"mu1": 0.5, "mu2": 0.5, "k_ip": math.inf})


@pytest.fixture(scope="module")
def onset_branch(soft):
    return harmonic_branch(soft, Axis("Omega", 30, 200), max_points=6)


def test_amplitude_follows_the_exact_normal_form_near_onset(onset_branch):
    b = onset_branch
    h = b.hopf.hopf
    assert h.p0 == pytest.approx(64.81, abs=0.01) and h.frequency0_hz == pytest.approx(1741, abs=1)
    assert h.criticality == "supercritical" and h.side == 1
    a = dict(zip(h.state_names, h.amplitude_coefficients))
    dev, dps = [], []
    for pt in b.points[:3]:
        dp = pt.p - h.p0
        assert dp > 0
        ratios = [pt.amplitude[c] / (a[c] * math.sqrt(dp)) for c in ("q1", "q2")]
        dev.append(max(abs(r - 1) for r in ratios))
        dps.append(dp)
        # frequency: omega0 + slope dp to O(dp^2)
        assert pt.omega - h.omega0 == pytest.approx(h.frequency_slope * dp, rel=0.05, abs=1e-9 * h.omega0)
        # Hill's method: the radial exponent of the normal form, -2 mu' dp; the trivial exponent 0
        radial = max(pt.floquet_exponents.real)
        assert radial == pytest.approx(-2 * h.dRe_lambda_dp * dp, rel=0.05)
        assert pt.trivial_exponent < 1e-9 * h.omega0 and pt.stable
    assert dps[0] < dps[1] < dps[2]
    # ratio -> 1 linearly in dp (the O(dp) correction of the amplitude law)
    assert dev[0] < 2e-4 and dev[0] < dev[2]
    assert dev[2] / dps[2] < 10 * max(dev[0] / dps[0], 1e-3)


def test_branch_points_report_contact_and_truncation(onset_branch):
    for pt in onset_branch.points:
        assert len(pt.F_n_min) == 2 and all(0 < f < 3000 for f in pt.F_n_min)  # preload 3000 N falls on the cycle
        assert pt.sliding_margin_min > 0
        assert pt.truncation_error <= 1e-6 and pt.residual < 1e-7
        assert pt.tilt_amplitude == max(pt.amplitude["q1"], pt.amplitude["q2"])
    d = onset_branch.to_dict()
    json.dumps(d)
    assert d["stability"] == "Hill's method" and len(d["points"]) == 6 and d["status"] == "max_points"


@pytest.mark.slow
def test_regularised_pads_converge_to_the_exact_branch_at_rate_S(soft):
    """Shooting on mu + S v (S = 4e-4, 2e-4, 1e-4) tends to the harmonic-balance branch at 75 rad/s as O(S).

    Measured (2026-11-27): relative amplitude errors 3.39e-2, 1.78e-2, 9.13e-3, frequency -7.5e-7, -3.76e-7,
    -1.88e-7."""
    ax = Axis("Omega", 60, 75)
    b = harmonic_branch(soft, ax, max_points=60)
    assert b.status == "range"
    P = b.points[-1]
    assert P.p == 75.0
    ea, ef = [], []
    for S in (4e-4, 2e-4, 1e-4):
        s = squeal_branch(soft, ax, pad_slope=S, max_points=60)
        ds = s.data
        assert s.branch.status == "range" and float(ds["p"].values[-1]) == pytest.approx(75.0, abs=1e-9)
        amp = dict(zip([str(c) for c in ds["coord"].values], ds["amplitude"].values[-1]))
        ea.append(max(abs(amp[c] / P.amplitude[c] - 1) for c in ("q1", "q2")))
        ef.append(abs(float(ds["frequency"].values[-1]) / P.frequency_hz - 1))
    for e in (ea, ef):
        assert 1.7 < e[0] / e[1] < 2.3 and 1.7 < e[1] / e[2] < 2.3  # O(S)
        assert abs(2 * e[2] - e[1]) < 0.15 * e[2]  # Richardson: the limit is the harmonic-balance branch
    assert ea[2] < 0.012 and ef[2] < 3e-7


@pytest.mark.slow
def test_rigid_pads_equal_the_shooting_branch(rigid):
    """k_ip = inf: the quasi-static pads of the shooting are exact; both routes give the same orbits."""
    ax = Axis("Omega", 30, 36)
    b = harmonic_branch(rigid, ax, max_points=60)
    s = squeal_branch(rigid, ax)
    assert b.status == "range" and s.branch.status == "range"
    P, ds = b.points[-1], s.data
    assert P.p == 36.0 and float(ds["p"].values[-1]) == pytest.approx(36.0, abs=1e-9)
    amp = dict(zip([str(c) for c in ds["coord"].values], ds["amplitude"].values[-1]))
    for c in ("q1", "q2"):
        assert P.amplitude[c] == pytest.approx(amp[c], rel=1e-7)
    assert P.frequency_hz == pytest.approx(float(ds["frequency"].values[-1]), rel=1e-10)
    assert P.truncation_error < 1e-8 and P.residual < 1e-8
    # Floquet multipliers exp(lambda T) of Hill's exponents against the shooting's monodromy matrix
    T = 2 * np.pi / P.omega
    hill = np.sort(np.abs(np.exp(P.floquet_exponents * T)))
    shot = np.sort(ds["floquet_abs"].values[-1])
    assert hill == pytest.approx(shot, abs=1e-7)
    # the located contact loss of both routes
    ax2 = Axis("Omega", 30, 37)
    b2 = harmonic_branch(rigid, ax2, max_points=60, stability=False)
    s2 = squeal_branch(rigid, ax2)
    assert b2.status == "contact_loss" and b2.points[-1].p == b2.contact_loss
    assert min(b2.points[-1].F_n_min) == pytest.approx(0, abs=1e-6 * 3000)
    assert b2.contact_loss == pytest.approx(s2.contact_loss, rel=1e-8)
    assert b2.points[-1].stable is None and b2.stability == "not computed"


def _independent_residual(space, pt, cm, t):
    """max_i |r_i| / (terms' magnitude) at times t, with the series and its derivatives written here."""
    from brakesqueal import simulation_model

    params = space.resolve({"Omega": pt.p})
    sim = simulation_model(params.model)
    p = [float(v) for v in sim.parameter_vector(params)]
    C, w, n = pt.coefficients, pt.omega, cm.n
    H = (C.shape[1] - 1) // 2
    k = np.arange(1, H + 1)
    a, b = C[:, 1::2], C[:, 2::2]
    amp = np.hypot(a[:, 0], b[:, 0])
    worst = 0.0
    for tt in t:
        c, s = np.cos(k * w * tt), np.sin(k * w * tt)
        u = C[:, 0] + a @ c + b @ s
        ud = (b * k * w) @ c - (a * k * w) @ s
        udd = -(a * (k * w) ** 2) @ c - (b * (k * w) ** 2) @ s
        x = [*u[:n], *ud[:n], *udd[:n], *u[n:], *ud[n:]]
        r = np.asarray(cm.residuals(x, p))
        J = cm.jacobian_matrix(x, p)
        xs = np.concatenate([amp[:n], w * amp[:n], w * w * amp[:n], amp[n:], w * amp[n:]])
        worst = max(worst, float(np.max(np.abs(r) / (np.abs(J) @ xs))))
    return worst


@pytest.mark.slow
def test_orbit_satisfies_the_equations_off_grid_and_truncation_shrinks(soft):
    from brakesqueal.codegen import compile_model

    cm = compile_model(soft.resolve({}).model)
    ax = Axis("Omega", 60, 72)
    rng = np.random.default_rng(14)
    res, trunc, amps = [], [], []
    for H in (4, 6, 9, 13):
        b = harmonic_branch(soft, ax, harmonics=H, max_harmonics=H, harmonic_tol=1.0, max_points=60,
                            stability=False)
        P = b.points[-1]
        assert b.status == "range" and P.p == 72.0 and P.harmonics == H
        t = rng.uniform(0, 2 * np.pi / P.omega, 997)
        res.append(_independent_residual(soft, P, cm, t))
        trunc.append(P.truncation_error)
        amps.append(P.amplitude["q1"])
        assert P.residual == pytest.approx(res[-1], rel=0.5)  # the module's own off-grid estimate
    assert all(x > y for x, y in zip(trunc, trunc[1:])) and all(x > y for x, y in zip(res, res[1:]))
    assert res[-1] < 1e-7 and trunc[-1] < 1e-6
    for i in range(3):  # the estimate bounds the change of the amplitude when the harmonics increase
        assert abs(amps[i] / amps[-1] - 1) < 10 * trunc[i]


def test_exact_jacobian_against_central_differences(onset_branch, soft):
    from brakesqueal import simulation_model
    from brakesqueal.nonlinear.harmonic import _Balance

    P = onset_branch.points[-1]
    H = P.harmonics
    scale = np.maximum(np.hypot(P.coefficients[:, 1], P.coefficients[:, 2]), 1e-9)
    bal = _Balance(soft, "Omega", simulation_model(soft), H, 0, scale)
    y = np.concatenate([P.coefficients.ravel(), [P.omega, P.p]])
    J = bal.jacobian(y)
    s = np.concatenate([np.repeat(scale, bal.K), [P.omega, 1.0]])
    rng = np.random.default_rng(3)
    for j in rng.choice(y.size, 12, replace=False).tolist() + [y.size - 2]:
        h = 1e-5 * s[j]
        e = np.zeros(y.size)
        e[j] = h
        fd = (bal.F(y + e) - bal.F(y - e)) / (2 * h)
        ref = np.max(np.abs(J[:, j])) + 1e-300
        assert np.max(np.abs(J[:, j] - fd)) < 1e-6 * ref


def test_bad_input_is_named(soft):
    with pytest.raises(ParameterError, match="no Hopf point"):
        harmonic_branch(soft, Axis("Omega", 30, 50))
    for bad in (0, -3, 2.5):
        with pytest.raises(ParameterError, match="harmonics"):
            harmonic_branch(soft, Axis("Omega", 30, 80), harmonics=bad)
    with pytest.raises(ParameterError, match="max_points"):
        harmonic_branch(soft, Axis("Omega", 30, 80), max_points=1)
    with pytest.raises(ParameterError, match="harmonic_tol"):
        harmonic_branch(soft, Axis("Omega", 30, 80), harmonic_tol=0.0)
    with pytest.raises(ParameterError, match="Omega"):
        harmonic_branch(soft, Axis("Omega", -10, 80))
    with pytest.raises(ParameterError, match="nonsense"):
        harmonic_branch(soft, Axis("nonsense", 1, 2))


def test_cli_exact_pads(capsys):
    args = ["cycles", "--preset", "paper-fig3", "--set", "mu1=0.5", "--set", "mu2=0.5", "--set", "k_ip1=1e6",
            "--set", "k_ip2=1e6", "--along", "Omega=30:80", "--exact-pads", "--max-points", "4"]
    assert main([*args, "--format", "json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["hopf"]["criticality"] == "supercritical" and len(d["points"]) == 4
    assert d["points"][0]["p"] > d["hopf"]["p0"] and d["points"][0]["stable"] is True
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "harmonic balance" in out and "Fn min 1" in out and out.count("yes") == 4
    assert main([*args, "--pad-slope", "1e-4"]) != 0
    assert "--pads exact" in capsys.readouterr().err
