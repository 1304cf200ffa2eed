"""Continuation of cycles: folds, period doubling, Neimark-Sacker at closed-form parameter values."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from _nl_systems import bautin, neimark_sacker, period_doubling, sympy_system, van_der_pol

from brakesqueal.errors import ParameterError
from brakesqueal.nonlinear import continue_cycles, find_periodic_orbit, first_lyapunov


@pytest.fixture(scope="module")
def bautin_branch():
    s = bautin()
    h = first_lyapunov(s, [0.0, 0.0], 0.0)
    return h, continue_cycles(s, h, (-0.5, 0.5), ds_max=0.1)


@pytest.mark.slow
def test_bautin_subcritical_hopf_fold_of_cycles_and_hysteresis(bautin_branch):
    """r' = r (mu + r^2 - r^4): subcritical Hopf at mu = 0 (l1 = 2 in MatCont's normalisation, see
    test_nl_hopf), cycles r^2 = (1 +- sqrt(1 + 4 mu)) / 2, fold at mu = -1/4 with r^2 = 1/2; the stable
    equilibrium and the stable large cycle coexist for -1/4 < mu < 0."""
    h, br = bautin_branch
    assert h.criticality == "subcritical" and h.side == -1
    kinds = [sp.kind for sp in br.special]
    assert kinds == ["H", "LPC", "EP"]
    lpc = br.special[1]
    assert lpc.p == pytest.approx(-0.25, abs=1e-9)
    assert lpc.amplitude[0] ** 2 == pytest.approx(0.5, abs=1e-8)
    assert abs(lpc.floquet[0] - 1) < 1e-7  # the second multiplier passes through 1 at the fold
    lo, hi = br.hysteresis_range
    assert lo == pytest.approx(-0.25, abs=1e-9) and hi == pytest.approx(0.0, abs=1e-14)
    assert br.status == "range" and br.special[-1].p == pytest.approx(0.5, abs=1e-12)
    d = br.data
    r = d["amplitude"].values[:, 0]
    p = d["p"].values
    # every point lies on the closed-form branch mu = r^4 - r^2, with its closed-form multiplier
    np.testing.assert_allclose(p, r**4 - r**2, atol=1e-9)
    np.testing.assert_allclose(d["period"].values, 2 * math.pi, rtol=1e-9)
    mu_exact = np.exp(2 * math.pi * (2 * r**2 - 4 * r**4))
    regular = d["label"].values == ""
    np.testing.assert_allclose(d["floquet_re"].values[regular, 0], mu_exact[regular], rtol=1e-7, atol=1e-12)
    assert np.all(d["trivial_multiplier_error"].values[1:] < 1e-8)
    # stability: unstable (r^2 < 1/2) before the fold, stable after it
    np.testing.assert_array_equal(d["stable"].values[1:][regular[1:]], (r**2 > 0.5)[1:][regular[1:]])
    assert d.attrs["hopf_criticality"] == "subcritical" and d.attrs["parameter"] == "mu"
    assert d["mu"].values[3] == p[3]
    assert d["orbit"].shape == (len(p), 64, 2)


def test_bautin_plot(bautin_branch):
    _, br = bautin_branch
    fig = br.plot()
    ax0, ax1 = fig.axes
    styles = {ln.get_linestyle() for ln in ax0.lines if len(ln.get_xdata()) > 1}
    assert {"-", "--"} <= styles  # stable solid, unstable dashed
    labels = [t.get_text() for t in ax0.get_legend().get_texts()]
    assert "H" in labels and "LPC" in labels
    with pytest.raises(ParameterError, match="coord"):
        br.plot(coord="nope")


def test_continuation_from_an_orbit_finds_the_same_fold():
    s = bautin()
    r2 = (1 + math.sqrt(1 + 4 * 0.1)) / 2
    o = find_periodic_orbit(s, [math.sqrt(r2), 0.0], period=6.3, p=0.1)
    br = continue_cycles(s, o, (-0.3, 0.2), direction=-1, ds_max=0.1, max_points=60)
    lpc = [sp for sp in br.special if sp.kind == "LPC"]
    assert len(lpc) == 1 and lpc[0].p == pytest.approx(-0.25, abs=1e-9)
    assert br.hysteresis_range is None  # no Hopf point on this branch


def test_period_doubling_at_closed_form_parameter():
    """Multipliers exp(-4 pi p), -exp(2 pi (-1 +- 2 sqrt p)): PD at p = 1/4 (see _nl_systems)."""
    s = period_doubling(d=2.0)
    h = first_lyapunov(s, np.zeros(4), 0.0)
    br = continue_cycles(s, h, (-0.1, 0.4), ds_max=0.1)
    pd = [sp for sp in br.special if sp.kind == "PD"]
    assert len(pd) == 1 and pd[0].p == pytest.approx(0.25, abs=1e-9)
    assert np.min(np.abs(pd[0].floquet + 1)) < 1e-8
    d = br.data
    p = d["p"].values[1:]
    exact = np.stack([-np.exp(2 * np.pi * (-1 + 2 * np.sqrt(p))), np.exp(-4 * np.pi * p),
                      -np.exp(2 * np.pi * (-1 - 2 * np.sqrt(p)))], axis=1)  # fmt: skip
    got = d["floquet_re"].values[1:]
    for row_g, row_e in zip(got, exact):
        np.testing.assert_allclose(np.sort(row_g), np.sort(row_e), rtol=1e-7, atol=1e-12)
    regular = d["label"].values[1:] == ""
    np.testing.assert_array_equal(d["stable"].values[1:][regular], (p < 0.25)[regular])
    assert not [k for k in (sp.kind for sp in br.special) if k in ("LPC", "NS", "BPC")]


def test_neimark_sacker_at_closed_form_parameter():
    """Multipliers exp(2 pi (-1 + 4 p)) exp(+-0.6 pi i): NS at p = 1/4 with argument 0.6 pi."""
    s = neimark_sacker(a=0.3, k=4.0)
    h = first_lyapunov(s, np.zeros(4), 0.0)
    br = continue_cycles(s, h, (-0.1, 0.4), ds_max=0.1)
    ns = [sp for sp in br.special if sp.kind == "NS"]
    assert len(ns) == 1 and ns[0].p == pytest.approx(0.25, abs=1e-9)
    pair = ns[0].floquet[np.abs(ns[0].floquet.imag) > 1e-3]
    np.testing.assert_allclose(np.abs(pair), 1.0, atol=1e-8)
    np.testing.assert_allclose(np.sort(np.abs(np.angle(pair))), [0.6 * np.pi] * 2, atol=1e-8)
    assert [k for k in (sp.kind for sp in br.special) if k not in ("H", "EP")] == ["NS"]


def test_supercritical_branch_agrees_with_prediction_and_independent_shooting():
    s = van_der_pol()
    h = first_lyapunov(s, [0.0, 0.0], 0.0)
    br = continue_cycles(s, h, (0.0, 1.0), ds_max=0.1, start_amplitude=0.01)
    d = br.data
    dp = d["p"].values[1:4] - h.p0
    ratio = d["amplitude"].values[1:4] / (h.amplitude_coefficients * np.sqrt(dp)[:, None])
    np.testing.assert_allclose(ratio, 1.0, atol=20 * dp.max())
    assert np.all(d["stable"].values) and br.special[0].kind == "H"
    k = len(d["p"]) // 2
    o = find_periodic_orbit(s, [2.0, 0.0], period=6.5, p=float(d["p"].values[k]))
    assert o.period == pytest.approx(float(d["period"].values[k]), rel=1e-9)
    np.testing.assert_allclose(o.amplitude, d["amplitude"].values[k], rtol=1e-8)


def test_branch_between_two_hopf_points_stops_at_the_second():
    """r' = r (mu (1 - mu) - r^2): cycles r^2 = mu (1 - mu) for 0 < mu < 1; the amplitude returns to 0."""
    x1, x2, mu = sp.symbols("x1 x2 mu", real=True)
    g = mu * (1 - mu) - x1**2 - x2**2
    s = sympy_system([g * x1 - x2, g * x2 + x1], [x1, x2], mu)
    h = first_lyapunov(s, [0, 0], 0.0)
    br = continue_cycles(s, h, (-0.5, 1.5), ds_max=0.1)
    assert br.status == "equilibrium"
    assert br.data["p"].values[-1] > 0.9
    assert float(br.message.split("near mu = " if "mu =" in br.message else "near p = ")[1].split()[0]) == pytest.approx(1.0, abs=0.02)
    r = br.data["amplitude"].values[:, 0]
    p = br.data["p"].values
    np.testing.assert_allclose(r**2, p * (1 - p), atol=1e-9)


def test_bad_options(bautin_branch):
    h, _ = bautin_branch
    s = bautin()
    with pytest.raises(ParameterError, match="p_range"):
        continue_cycles(s, h, (0.5, -0.5))
    with pytest.raises(ParameterError, match="p_range"):
        continue_cycles(s, h, (0.1, 0.5))
    with pytest.raises(ParameterError, match="detect"):
        continue_cycles(s, h, (-0.5, 0.5), detect=("XYZ",))
    with pytest.raises(ParameterError, match="outside p_range"):
        continue_cycles(s, h, (0.0, 0.5))
    deg = first_lyapunov(bautin(beta=0.0), [0, 0], 0.0)
    with pytest.raises(ParameterError, match="degenerate"):
        continue_cycles(bautin(beta=0.0), deg, (-0.5, 0.5))


def test_branch_in_si_units_matches_the_dimensionless_system():
    """Brake-like scaling (omega ~ 1e4 rad/s, angles ~ 1e-5 rad): every branch point is an orbit of the
    dimensionless system (independent shooting there) with period x 1e-4 and amplitudes x diag(S)."""
    from _nl_systems import friction_oscillator
    from test_nl_hopf import _si_scaled

    base = friction_oscillator()
    S, s = _si_scaled(base)
    h = first_lyapunov(s, np.zeros(4), 0.2509980079602)
    br = continue_cycles(s, h, (h.p0, h.p0 + 0.002), max_points=8)
    d = br.data
    assert np.all(d["trivial_multiplier_error"].values[1:] < 1e-8)
    for k in (2, 7):
        x0 = np.linalg.solve(S, d["x0"].values[k])
        o = find_periodic_orbit(base, x0, period=float(d["period"].values[k]) * 1e4, p=float(d["p"].values[k]))
        assert float(d["period"].values[k]) * 1e4 == pytest.approx(o.period, rel=1e-10)
        np.testing.assert_allclose(d["amplitude"].values[k], o.amplitude * np.diag(S), rtol=1e-8)
        np.testing.assert_allclose(d["floquet_abs"].values[k], np.abs(o.floquet), rtol=1e-7)
