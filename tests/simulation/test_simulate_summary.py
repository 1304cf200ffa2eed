"""The simulation summary: leading-mode growth rate and frequency with an uncertainty (issue 10, items 3 and 7).

Reference values are computed here, independently of the code under test:

* eigenvalues of the linearization from ``M, D, K`` (``brakesqueal.linearize``) with a state matrix assembled in
  the test and ``scipy.linalg.eigvals``;
* synthetic motions from chosen eigenvalues and eigenvectors (``A = V diag(lambda) V^-1``), evaluated in closed
  form, so that the true growth rates and frequencies are known exactly.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import scipy.linalg as sla

from brakesqueal import linearize, simulate
from brakesqueal.cli import main
from brakesqueal.errors import ParameterError
from brakesqueal.model import get_preset
from brakesqueal.simulation import (
    dominant_mode,
    fit_growth_frequency,
    linear_modes,
    matrix_pencil,
    modal_projection,
)

TWO_PI = 2 * math.pi


# ----------------------------------------------------------------------------- independent references
def leading_eigenvalue(params) -> complex:
    """Leading eigenvalue (largest real part, Im > 0) of the state matrix built here from M, D, K."""
    lm = linearize(params)
    M, D, K = np.asarray(lm.M), np.asarray(lm.D), np.asarray(lm.K)
    n = M.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-sla.solve(M, K), -sla.solve(M, D)]])
    lam = sla.eigvals(A)
    lam = lam[lam.imag > 0]
    return complex(lam[np.argmax(lam.real)])


def synthetic_system(rng, lams, n=2):
    """Real state matrix with the chosen complex eigenvalues (and conjugates), random eigenvectors."""
    m = 2 * n
    V = np.empty((m, m), complex)
    for k in range(n):
        v = rng.standard_normal(m) + 1j * rng.standard_normal(m)
        V[:, 2 * k], V[:, 2 * k + 1] = v, v.conj()
    L = np.empty(m, complex)
    L[0::2], L[1::2] = lams, np.conj(lams)
    A = (V @ np.diag(L) @ np.linalg.inv(V)).real
    return A, V, L


def motion(t, V, L, c):
    """x(t) = V exp(L t) c for real-valued c pairs (c[2k+1] = conj c[2k])."""
    return (np.exp(np.outer(t, L)) * c) @ V.T


def pair_coefficients(rng, n, scale=1.0):
    c = np.empty(2 * n, complex)
    c[0::2] = scale * (rng.standard_normal(n) + 1j * rng.standard_normal(n))
    c[1::2] = np.conj(c[0::2])
    return c


# ----------------------------------------------------------------------------- the estimators on synthetic data
def test_linear_modes_are_biorthonormal(rng):
    for _ in range(5):
        lams = rng.uniform(-3, 3, 3) + 1j * rng.uniform(50, 500, 3)
        A, _, L = synthetic_system(rng, lams, n=3)
        md = linear_modes(A)
        np.testing.assert_allclose(np.sort_complex(md.eigenvalues), np.sort_complex(L), rtol=1e-9)
        assert md.eigenvalues[0].real == pytest.approx(max(lams.real)) and md.eigenvalues[0].imag > 0
        np.testing.assert_allclose(md.left.conj().T @ md.right, np.eye(6), atol=1e-9)
        np.testing.assert_allclose(A @ md.right, md.right * md.eigenvalues, atol=1e-8 * np.abs(A).max())


def test_modal_projection_removes_beating_of_close_modes(rng):
    """Two modes 1 % apart in frequency, comparable amplitudes: the projection is exact, the envelope fit is not."""
    for _ in range(6):
        f1 = rng.uniform(200, 2000)
        lam1 = complex(rng.uniform(-2, 2), TWO_PI * f1)
        lam2 = complex(lam1.real - rng.uniform(0.5, 3), TWO_PI * f1 * (1 - rng.uniform(0.005, 0.02)))
        A, V, L = synthetic_system(rng, np.array([lam1, lam2]))
        t = np.arange(0, 0.5, 1 / (20 * f1))
        x = motion(t, V, L, pair_coefficients(rng, 2)).real
        e = modal_projection(t, x, linear_modes(A))
        assert e.estimator == "modal-projection"
        assert abs(e.growth_rate - lam1.real) <= 1e-7 * abs(lam1)
        assert abs(TWO_PI * e.frequency_hz - lam1.imag) <= 1e-9 * abs(lam1)
        assert abs(e.growth_rate - lam1.real) <= max(e.growth_rate_stderr, 1e-9 * abs(lam1))
    # negative control: the envelope fit on the same kind of data is biased by the beating
    g_env, _ = fit_growth_frequency(t, x[:, :2])
    assert abs(g_env - lam1.real) > 1e-3


def test_projection_uncertainty_is_calibrated_with_noise(rng):
    """White noise on the samples: the reported uncertainty covers the error and is not wildly pessimistic."""
    lam = complex(0.7, TWO_PI * 300.0)
    A, V, L = synthetic_system(rng, np.array([lam, complex(-1.0, TWO_PI * 330.0)]))
    md = linear_modes(A)
    t = np.arange(0, 0.2, 1 / 6000)
    clean = motion(t, V, L, np.array([1, 1, 0.5, 0.5], complex)).real
    errs, ses, ferrs, fses = [], [], [], []
    for _ in range(200):
        x = clean + 1e-3 * rng.standard_normal(clean.shape)
        e = modal_projection(t, x, md)
        errs.append(e.growth_rate - lam.real)
        ses.append(e.growth_rate_stderr)
        ferrs.append(TWO_PI * e.frequency_hz - lam.imag)
        fses.append(TWO_PI * e.frequency_stderr)
    errs, ses, ferrs, fses = map(np.asarray, (errs, ses, ferrs, fses))
    assert np.mean(np.abs(errs) <= 2 * ses) >= 0.95 and np.mean(np.abs(ferrs) <= 2 * fses) >= 0.95
    assert np.median(ses) <= 4 * errs.std() and np.median(fses) <= 4 * ferrs.std()
    assert abs(errs.mean()) < 3 * errs.std() / math.sqrt(errs.size) + 1e-12  # unbiased


def test_projection_with_undersampled_data_warns_but_demodulates():
    rng = np.random.default_rng(3)
    lam = complex(-0.4, TWO_PI * 1739.0)
    A, V, L = synthetic_system(rng, np.array([lam, complex(-1.5, TWO_PI * 1721.0)]))
    t = np.arange(0, 5, 1 / 10.0)  # 10 Hz: far below the Nyquist rate
    x = motion(t, V, L, pair_coefficients(rng, 2)).real
    e = modal_projection(t, x, linear_modes(A))
    assert any("aliased" in w for w in e.warnings)
    assert abs(e.growth_rate - lam.real) < 1e-9 * abs(lam)  # exact linear motion: the projection is pointwise
    assert abs(TWO_PI * e.frequency_hz - lam.imag) < 1e-9 * abs(lam)


def test_matrix_pencil_separates_close_modes_with_noise(rng):
    for _ in range(3):
        f1 = rng.uniform(40, 60)
        lams = np.array([complex(rng.uniform(-1, 1), TWO_PI * f1), complex(-2.0, TWO_PI * f1 * 1.03)])
        _, V, L = synthetic_system(rng, lams)
        t = np.linspace(0, 1.5, 450)  # 4.8 to 7.5 samples per period; over 1.5 s the modes 3 % apart beat twice
        x = motion(t, V, L, pair_coefficients(rng, 2)).real
        x_noisy = x + 1e-5 * np.abs(x).max() * rng.standard_normal(x.shape)
        pm = matrix_pencil(t, x_noisy)
        for lam in lams:
            assert np.min(np.abs(pm.eigenvalues - lam)) < 1e-2, (lam, pm.eigenvalues)
        # the reference picks the requested mode; its estimate and uncertainty bracket the truth
        for lam in lams:
            r = dominant_mode(t, x_noisy, reference=lam, max_samples=450)
            assert abs(complex(r.growth_rate, TWO_PI * r.frequency_hz) - lam) < 5e-3
            assert abs(r.growth_rate - lam.real) <= 5 * r.growth_rate_stderr + 1e-6


def test_dominant_mode_is_the_largest_at_the_end():
    rng = np.random.default_rng(11)
    lams = np.array([complex(1.0, TWO_PI * 80.0), complex(-3.0, TWO_PI * 95.0)])
    _, V, L = synthetic_system(rng, lams)
    t = np.arange(0, 2.0, 1 / 500)
    big_early = np.array([0.05, 0.05, 3.0, 3.0], complex)  # the decaying mode is larger at the start
    x = motion(t, V, L, big_early).real
    d = dominant_mode(t, x, max_samples=400)
    assert d.window[1] == t[-1]
    assert abs(complex(d.growth_rate, TWO_PI * d.frequency_hz) - lams[0]) < 1e-6 * abs(lams[0])
    early = dominant_mode(t[:100], x[:100])
    assert abs(complex(early.growth_rate, TWO_PI * early.frequency_hz) - lams[1]) < 1e-6 * abs(lams[1])


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: matrix_pencil(np.r_[0, 1, 3, 4, 5, 6, 7, 8, 9.0], np.ones(9)), "uniform"),
        (lambda: matrix_pencil(np.arange(5.0), np.ones(5)), "at least 8"),
        (lambda: modal_projection(np.arange(10.0), np.ones((9, 4)), linear_modes(np.eye(4))), "shape"),
        (lambda: linear_modes(np.ones((3, 2))), "square"),
    ],
)
def test_estimator_bad_input(call, match):
    with pytest.raises(ParameterError, match=match):
        call()


# ----------------------------------------------------------------------------- the default simulation
def _draw_points(seed=20261123):
    """Seeded parameter points of both presets, two stable and two unstable each (classified independently)."""
    rng = np.random.default_rng(seed)
    out = []
    for preset, draw in (
        ("paper-fig2", lambda: {"mu": rng.uniform(0.1, 1.0), "k_ip": 10 ** rng.uniform(6, 9)}),
        ("paper-fig3", lambda: {"mu1": rng.uniform(0.1, 1.0), "mu2": rng.uniform(0.1, 1.0),
                                "Omega": rng.uniform(5.0, 200.0)}),  # fmt: skip
    ):
        got = {True: 0, False: 0}
        while min(got.values()) < 2:
            o = draw()
            params = get_preset(preset).resolve(o)
            lam = leading_eigenvalue(params)
            if abs(lam.real) < 0.02 or got[lam.real > 0] >= 2:
                continue
            got[lam.real > 0] += 1
            out.append((preset, o, params, lam))
    return out


POINTS = _draw_points()


def _check_against_linear(s, lam):
    assert s.estimator == "modal-projection"
    dg, dw = s.growth_rate - lam.real, TWO_PI * s.frequency_hz - lam.imag
    # within the reported uncertainty ...
    assert abs(dg) <= s.growth_rate_stderr, (dg, s.growth_rate_stderr)
    assert abs(dw) <= TWO_PI * s.frequency_stderr, (dw, s.frequency_stderr)
    # ... and within a fixed tolerance relative to |lambda| (Re lambda itself may be near zero)
    assert abs(dg) <= 1e-8 * abs(lam) and abs(dw) <= 1e-8 * abs(lam)
    # the uncertainty is small enough to decide stability
    assert 3 * s.growth_rate_stderr < abs(lam.real) and (s.growth_rate > 0) == (lam.real > 0)
    assert s.regime == "linear"


@pytest.mark.parametrize("preset, overrides, params, lam", POINTS, ids=[f"{p}-{i}" for i, (p, *_) in
                                                                        enumerate(POINTS)])  # fmt: skip
def test_default_run_gives_the_leading_eigenvalue(preset, overrides, params, lam):
    tr = simulate(params, 0.5)
    assert tr.status == "finished", tr.message
    s = tr.summary
    _check_against_linear(s, lam)
    assert s.warnings == ()
    assert s.cross_check is not None and abs(s.cross_check["growth_rate"] - lam.real) <= 1e-8 * abs(lam)
    assert s.linear_growth_rate == pytest.approx(lam.real, rel=1e-9, abs=1e-9 * abs(lam))


@pytest.mark.parametrize("k", [0, 2, 5])
def test_default_cli_run_gives_the_leading_eigenvalue(k, capsys):
    preset, overrides, params, lam = POINTS[k]
    sets = [a for name, v in overrides.items() for a in ("--set", f"{name}={v!r}")]
    rc = main(["simulate", "--preset", preset, *sets, "--t-end", "0.5", "--format", "json", "--no-progress"])
    out = capsys.readouterr()
    assert rc == 0 and out.err == ""
    d = json.loads(out.out)
    for key in ("status", "frequency_hz", "growth_rate", "amplitude_final", "limit_cycle_amplitude",
                "growth_rate_stderr", "frequency_stderr", "estimator", "warnings", "start"):  # fmt: skip
        assert key in d
    assert d["start"].startswith("leading mode")
    assert abs(d["growth_rate"] - lam.real) <= min(d["growth_rate_stderr"], 1e-8 * abs(lam))
    assert abs(TWO_PI * d["frequency_hz"] - lam.imag) <= min(TWO_PI * d["frequency_stderr"], 1e-8 * abs(lam))


def test_default_start_is_along_the_leading_mode():
    params = get_preset("paper-fig2").resolve()
    tr = simulate(params, 0.001)
    x0 = tr.y[0] - np.r_[tr.q_m0, 0.0, 0.0]
    assert np.abs(x0[:2]).max() == pytest.approx(1e-5, rel=1e-12)
    lm = linearize(params)
    w, V = np.linalg.eig(lm.A)  # independent: components c = V^-1 x0
    c = np.linalg.solve(V, x0)
    lead = np.argsort(-w.real)[:2]
    other = np.setdiff1d(np.arange(4), lead)
    assert np.abs(c[other]).max() <= 1e-9 * np.abs(c[lead]).max()


def test_generic_start_no_longer_biased_by_beating():
    """The reported case (q0 = (1e-5, 0) excites both modes): the summary still gives Re lambda."""
    params = get_preset("paper-fig2").resolve()
    lam = leading_eigenvalue(params)
    tr = simulate(params, 0.5, perturbation=[1e-5, 0.0])
    _check_against_linear(tr.summary, lam)
    # negative control: the former envelope fit on the same samples reported about -0.037 1/s
    g_env, _ = fit_growth_frequency(tr.t, tr.dq)
    assert abs(g_env - lam.real) > 0.1


# ----------------------------------------------------------------------------- aliasing and memory
def test_low_output_rate_keeps_the_summary_and_warns():
    params = get_preset("paper-fig2").resolve({"mu": 0.3})
    lam = leading_eigenvalue(params)
    fine = simulate(params, 0.5)
    coarse = simulate(params, 0.5, sample_rate=10.0)
    assert coarse.t.size == 6
    s = coarse.summary
    _check_against_linear(s, lam)
    assert s.growth_rate == pytest.approx(fine.summary.growth_rate, rel=1e-12)
    assert s.frequency_hz == pytest.approx(fine.summary.frequency_hz, rel=1e-14)
    assert any("below twice the leading frequency" in w for w in s.warnings)
    assert not fine.summary.warnings
    # the same at a rate between the frequency and twice the frequency
    mid = simulate(params, 0.2, sample_rate=3000.0).summary
    _check_against_linear(mid, lam)
    assert any("below twice" in w for w in mid.warnings)


def test_high_frequency_parameters_with_a_low_sample_rate():
    """A stiffer support pushes the squeal frequency above the output rate; the summary is still right."""
    params = get_preset("paper-fig2").resolve().replace(k_t=9 * 18.8e6)
    lam = leading_eigenvalue(params)
    assert lam.imag / TWO_PI > 5000
    tr = simulate(params, 0.3, sample_rate=4000.0)
    s = tr.summary
    _check_against_linear(s, lam)
    assert s.estimate_rate_hz > 20 * lam.imag / TWO_PI * 0.99
    assert any("below twice" in w for w in s.warnings)


def test_cli_warns_on_stderr_for_an_aliased_output_rate(capsys):
    params = get_preset("paper-fig2").resolve({"mu": 0.3})
    lam = leading_eigenvalue(params)
    rc = main(["simulate", "--set", "mu=0.3", "--t-end", "2", "--sample-rate", "10", "--format", "json",
               "--no-progress"])  # fmt: skip
    out = capsys.readouterr()
    assert rc == 0
    err = out.err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("brakesqueal: warning:") and "below twice" in err[0]
    d = json.loads(out.out)
    assert any("below twice" in w for w in d["warnings"])
    assert abs(TWO_PI * d["frequency_hz"] - lam.imag) <= 1e-8 * abs(lam)
    assert abs(d["growth_rate"] - lam.real) <= d["growth_rate_stderr"]


def test_estimation_record_is_bounded():
    params = get_preset("paper-fig2").resolve({"mu": 0.8})
    lam = leading_eigenvalue(params)
    tr = simulate(params, 0.5, estimate_samples=4096)
    r = tr.record
    assert r.y.shape == (4096, 4) and not r.complete
    assert r.t[-1] == pytest.approx(0.5, abs=1 / r.rate) and np.allclose(np.diff(r.t), 1 / r.rate)
    s = tr.summary
    assert s.estimate_window[0] == pytest.approx(r.t[0]) and s.estimate_window[0] > 0.35
    _check_against_linear(s, lam)
    # the record agrees with the output grid where both have samples (same dense output)
    j = np.searchsorted(tr.t, r.t[0])
    k = np.flatnonzero(np.isin(np.round(r.t, 12), np.round(tr.t[j:], 12)))
    if k.size:
        i = np.searchsorted(tr.t, r.t[k])
        np.testing.assert_allclose(r.y[k], tr.y[i], rtol=0, atol=1e-12)


def test_scipy_method_fills_the_record_in_chunks():
    params = get_preset("paper-fig2").resolve({"mu": 1.0, "h": 0.05})
    lam = leading_eigenvalue(params)
    a = simulate(params, 0.05, estimate_samples=256, rtol=1e-10)
    b = simulate(params, 0.05, estimate_samples=256, rtol=1e-10, method="DOP853")
    assert np.array_equal(a.record.t, b.record.t)
    scale = np.abs(a.record.y).max(axis=0)
    assert (np.abs(a.record.y - b.record.y).max(axis=0) / scale).max() < 1e-6
    assert a.t.size == b.t.size and (np.abs(a.y - b.y).max(axis=0) / np.abs(a.y).max(axis=0)).max() < 1e-6
    for tr in (a, b):
        assert abs(tr.summary.growth_rate - lam.real) <= tr.summary.growth_rate_stderr


def test_cli_refuses_q0_with_x0(capsys):
    rc = main(["simulate", "--t-end", "0.01", "--no-progress", "--q0", "1e-5,0", "--x0", "0,0,0,0"])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "--q0" in err and "--x0" in err


def test_large_amplitude_is_flagged_nonlinear_and_matches_the_motion():
    """At 2e-3 rad the growth rate is amplitude-dependent: the summary says so, and it still describes the motion.

    Independent measures on the same dense record: the mean period of the upward zero crossings and the slope of
    log|peak| of q1 and q2 (cubic-spline interpolation).
    """
    from scipy.interpolate import CubicSpline

    params = get_preset("paper-fig2").resolve({"mu": 1.0, "h": 0.05})
    lam = leading_eigenvalue(params)
    lm = linearize(params)
    w, V = np.linalg.eig(lm.A)
    v = V[:, np.argmin(np.abs(w - lam))]
    v = np.real(v / v[np.argmax(np.abs(v[:2]))])
    tr = simulate(params, 0.3, perturbation=2e-3 * v)
    assert tr.status == "contact-loss"
    s = tr.summary
    assert s.regime == "nonlinear" and abs(s.growth_rate - lam.real) > 3 * s.growth_rate_stderr
    x = tr.record.y - np.r_[tr.q_m0, 0.0, 0.0]
    t = tr.record.t
    freqs, growths = [], []
    for j in range(2):
        cs = CubicSpline(t, x[:, j])
        roots = cs.roots(extrapolate=False)
        up = roots[cs(roots, 1) > 0]
        freqs.append(1 / np.polyfit(np.arange(up.size), up, 1)[0])
        ext = cs.derivative().roots(extrapolate=False)
        growths.append(np.polyfit(ext, np.log(np.abs(cs(ext))), 1)[0])
    assert abs(s.growth_rate - np.mean(growths)) <= 5 * s.growth_rate_stderr
    assert abs(s.frequency_hz - np.mean(freqs)) <= 5 * s.frequency_stderr
