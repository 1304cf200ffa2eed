"""Polynomial chaos surrogates (issue 27, item 3): ``fit_pce`` / ``fit_study_pce``.

References independent of the library's basis: the Ishigami function's analytic indices; random polynomials built
with ``numpy.polynomial`` (Legendre, Hermite_e) from known coefficients; chaospy's regression and indices on the
same runs; the Monte Carlo indices and P(squeal) of ``run_uq`` on the paper's model.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from brakesqueal.errors import ParameterError
from brakesqueal.uq import Distribution, fit_pce, fit_study_pce, pce_basis_size, pce_design

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "study-uq-mu.toml"

A_ISH, B_ISH = 7.0, 0.1
_V = A_ISH**2 / 8 + B_ISH * math.pi**4 / 5 + B_ISH**2 * math.pi**8 / 18 + 0.5
ISH_FIRST = np.array([0.5 * (1 + B_ISH * math.pi**4 / 5) ** 2, A_ISH**2 / 8, 0.0]) / _V
ISH_TOTAL = np.array([0.5 * (1 + B_ISH * math.pi**4 / 5) ** 2 + 8 * B_ISH**2 * math.pi**8 / 225, A_ISH**2 / 8,
                      8 * B_ISH**2 * math.pi**8 / 225]) / _V
ISH_DISTS = [Distribution(f"x{i}", "uniform", (-math.pi, math.pi)) for i in range(3)]


def ishigami(x: dict) -> np.ndarray:
    return np.sin(x["x0"]) + A_ISH * np.sin(x["x1"]) ** 2 + B_ISH * x["x2"] ** 4 * np.sin(x["x0"])


@pytest.mark.parametrize("runs, degree, sparse", [(512, 8, False), (256, 12, True)])
def test_ishigami_indices_within_0_01(runs, degree, sparse):
    x = pce_design(ISH_DISTS, runs, seed=1)
    s = fit_pce(x, ishigami(x), ISH_DISTS, degree=degree, sparse=sparse)
    assert np.abs(s.first - ISH_FIRST).max() < 0.01
    assert np.abs(s.total - ISH_TOTAL).max() < 0.01
    assert s.loo_error < 0.01 and s.r2 > 0.99
    assert abs(s.mean - 3.5) < 0.05 and abs(s.variance - _V) / _V < 0.01  # mean a/2, variance V
    if sparse:  # 455 candidate terms from 256 runs: only a sparse fit can, and it keeps fewer terms than runs
        assert s.candidates == pce_basis_size(3, 12) == 455 and s.indices.shape[0] < runs // 2
    # the surrogate predicts fresh points
    xt = pce_design(ISH_DISTS, 1024, seed=99)
    err = np.sqrt(np.mean((s(xt) - ishigami(xt)) ** 2) / _V)
    assert err < 0.1


def _orthonormal(kind: str, k: int, xi: np.ndarray) -> np.ndarray:
    """Degree-k orthonormal polynomial from numpy.polynomial (independent of the library's recurrences)."""
    c = np.zeros(k + 1)
    c[k] = 1.0
    if kind == "legendre":
        return np.polynomial.legendre.legval(xi, c) * math.sqrt(2 * k + 1)
    return np.polynomial.hermite_e.hermeval(xi, c) / math.sqrt(math.factorial(k))


def _random_dist(rng, name: str) -> Distribution:
    kind = rng.choice(["uniform", "normal", "truncnormal", "lognormal", "beta"])
    lo = float(rng.uniform(-5, 5))
    w = float(10 ** rng.uniform(-3, 6))  # widths from 1e-3 to 1e6: units must not matter
    return {"uniform": Distribution(name, "uniform", (lo, lo + w)),
            "normal": Distribution(name, "normal", (lo, w)),
            "truncnormal": Distribution(name, "truncnormal", (lo, w, lo - w * rng.uniform(0.2, 2),
                                                              lo + w * rng.uniform(0.2, 2))),
            "lognormal": Distribution(name, "lognormal", (w, float(rng.uniform(0.1, 1.0)))),
            "beta": Distribution(name, "beta", (float(rng.uniform(0.5, 4)), float(rng.uniform(0.5, 4)), lo,
                                                lo + w))}[str(kind)]


def _germ(d: Distribution, x: np.ndarray) -> np.ndarray:
    """Germ of the module docstring, written out independently."""
    if d.kind == "uniform":
        return (x - d.params[0]) / (d.params[1] - d.params[0]) * 2 - 1
    if d.kind == "normal":
        return (x - d.params[0]) / d.params[1]
    if d.kind == "lognormal":
        return (np.log(x) - np.log(d.params[0])) / d.params[1]
    return 2 * d.frozen().cdf(x) - 1


@pytest.mark.parametrize("case", range(12))
def test_random_polynomials_are_recovered_exactly(case):
    """Random distributions of every kind (widths 1e-3..1e6), a random polynomial of degree <= 3 in the germs
    with known coefficients: the fit returns them, the indices they imply, and a leave-one-out error ~ 0."""
    rng = np.random.default_rng(1000 + case)
    d = int(rng.integers(1, 5))
    dists = [_random_dist(rng, f"p{i}") for i in range(d)]
    terms = {tuple(0 for _ in range(d)): float(rng.normal())}
    while len(terms) < 4:
        a = tuple(int(v) for v in rng.integers(0, 4, d))
        if 0 < sum(a) <= 3:
            terms[a] = float(rng.normal())
    x = pce_design(dists, 256, seed=case)
    kinds = ["legendre" if dd.kind in ("uniform", "truncnormal", "beta") else "hermite" for dd in dists]
    y = np.zeros(256)
    for a, c in terms.items():
        y += c * np.prod([_orthonormal(kinds[i], a[i], _germ(dists[i], x[f"p{i}"])) for i in range(d)], axis=0)
    s = fit_pce(x, y, dists, degree=3, sparse=bool(case % 2))
    got = {tuple(int(v) for v in a): c for a, c in zip(s.indices, s.coefficients)}
    for a in set(got) | set(terms):
        assert abs(got.get(a, 0.0) - terms.get(a, 0.0)) < 1e-6, (a, got.get(a), terms.get(a))
    var = sum(c * c for a, c in terms.items() if sum(a))
    first = [sum(c * c for a, c in terms.items() if a[i] and sum(a) == a[i]) / var for i in range(d)]
    total = [sum(c * c for a, c in terms.items() if a[i]) / var for i in range(d)]
    np.testing.assert_allclose(s.first, first, atol=1e-8)
    np.testing.assert_allclose(s.total, total, atol=1e-8)
    assert s.loo_error < 1e-12


def test_physical_units_give_the_same_numbers_or_are_refused():
    """The same runs in physical units, in other physical units (the distribution rescaled with them) and as germs
    (standard distributions) give the same surrogate; inputs in units other than their distribution's are refused."""
    dists = [Distribution("mu", "uniform", (0.35, 0.55)), Distribution("k_ip", "lognormal", (1e8, 0.7)),
             Distribution("d1", "truncnormal", (5.0, 2.0, 0.5, 10.0)), Distribution("h", "normal", (2e-3, 5e-4)),
             Distribution("b", "beta", (2.0, 3.0, 1e5, 4e5))]
    x = pce_design(dists, 512, seed=3)
    g = {"mu": (x["mu"] - 0.45) / 0.1, "k_ip": np.log(x["k_ip"] / 1e8) / 0.7, "h": (x["h"] - 2e-3) / 5e-4,
         "d1": 2 * dists[2].frozen().cdf(x["d1"]) - 1, "b": 2 * dists[4].frozen().cdf(x["b"]) - 1}
    y = (np.sin(3 * g["mu"]) + 0.5 * g["k_ip"] * g["d1"] + 0.3 * g["h"] ** 2 + 0.2 * np.exp(g["b"])
         + 0.1 * g["mu"] * g["h"])
    ref = fit_pce(x, y, dists, degree=3)
    std = [Distribution("mu", "uniform", (-1, 1)), Distribution("k_ip", "normal", (0, 1)),
           Distribution("d1", "uniform", (-1, 1)), Distribution("h", "normal", (0, 1)),
           Distribution("b", "uniform", (-1, 1))]
    # other units: mu in percent, k_ip in N/mm, h in mm, b in kN/m (the distributions in the same units)
    scale = {"mu": 100.0, "k_ip": 1e-3, "d1": 1.0, "h": 1e3, "b": 1e-3}
    other = [Distribution("mu", "uniform", (35.0, 55.0)), Distribution("k_ip", "lognormal", (1e5, 0.7)),
             dists[2], Distribution("h", "normal", (2.0, 0.5)), Distribution("b", "beta", (2.0, 3.0, 100.0, 400.0))]
    for fit in (fit_pce(g, y, std, degree=3), fit_pce({k: v * scale[k] for k, v in x.items()}, y, other, degree=3),
                fit_pce(np.column_stack([x[d.name] for d in dists]), y, dists, degree=3)):
        np.testing.assert_allclose(fit.first, ref.first, rtol=1e-7, atol=1e-10)
        np.testing.assert_allclose(fit.total, ref.total, rtol=1e-7, atol=1e-10)
        assert fit.loo_error == pytest.approx(ref.loo_error, rel=1e-6)
        assert fit.probability(1.0, n=1 << 16) == ref.probability(1.0, n=1 << 16)
    assert ref.first[0] > 0.3  # the indices are not trivial
    # refused: germs with physical distributions, physical values with another unit's distribution
    for bad, name in ((g, "mu"), ({**x, "k_ip": x["k_ip"] * 1e-3}, "k_ip"), ({**x, "h": x["h"] * 1e3}, "h"),
                      ({**x, "mu": x["mu"] * 100}, "mu"), ({**x, "b": x["b"] * 1e-3}, "b"),
                      ({**x, "h": 1.6e-3 + 0.2 * x["h"]}, "h")):  # the last: a fifth of the spread
        with pytest.raises(ParameterError) as e:
            fit_pce(bad, y, dists, degree=3)
        msg = str(e.value)
        assert "\n" not in msg and f"input '{name}'" in msg and "units" in msg, msg


def test_agrees_with_chaospy():
    """chaospy's own expansion, regression and Sobol' indices on the same runs (the reference implementation)."""
    cp = pytest.importorskip("chaospy")
    dists = [Distribution("a", "uniform", (1.0, 3.0)), Distribution("b", "normal", (10.0, 2.0)),
             Distribution("c", "uniform", (-1.0, 0.0))]
    x = pce_design(dists, 128, seed=8)
    y = np.exp(0.3 * x["a"]) * np.cos(0.1 * x["b"]) + x["a"] * x["c"] ** 2
    s = fit_pce(x, y, dists, degree=4)
    joint = cp.J(cp.Uniform(1.0, 3.0), cp.Normal(10.0, 2.0), cp.Uniform(-1.0, 0.0))
    basis = cp.generate_expansion(4, joint, normed=True)
    model = cp.fit_regression(basis, np.vstack([x["a"], x["b"], x["c"]]), y)
    np.testing.assert_allclose(s.first, cp.Sens_m(model, joint), atol=1e-8)
    np.testing.assert_allclose(s.total, cp.Sens_t(model, joint), atol=1e-8)
    np.testing.assert_allclose(s.mean, float(cp.E(model, joint)), rtol=1e-10)
    xt = pce_design(dists, 64, seed=9)
    np.testing.assert_allclose(s(xt), model(xt["a"], xt["b"], xt["c"]), rtol=1e-8, atol=1e-10)


def test_leave_one_out_error_is_the_closed_form_of_refitting():
    """The reported leave-one-out error equals the one of n refits without each run."""
    dists = [Distribution("u", "uniform", (0.0, 1.0)), Distribution("v", "normal", (0.0, 3.0))]
    x = pce_design(dists, 40, seed=2)
    y = np.tanh(6 * x["u"] - 3) + 0.1 * x["v"]
    s = fit_pce(x, y, dists, degree=3)
    from brakesqueal.uq._surrogate import _design_matrix

    psi = _design_matrix(dists, s.germ(x), s.indices)
    res = []
    for i in range(40):
        keep = np.arange(40) != i
        c = np.linalg.lstsq(psi[keep], y[keep], rcond=None)[0]
        res.append(y[i] - psi[i] @ c)
    assert s.loo_error == pytest.approx(np.mean(np.square(res)) / np.var(y), rel=1e-8)
    assert s.loo_error > 1e-4  # a cubic does not fit tanh exactly: the error is not trivially zero


def test_paper_model_surrogate_reproduces_monte_carlo():
    """The example study (paper's model, mu uniform, k_ip lognormal, d1 truncnormal): a degree-6 expansion (and a
    sparse degree-10 one) from 256 runs gives the Monte Carlo indices of max Re λ (run_uq, 5 x 32768 evaluations)
    within 0.01 and P(squeal) within 0.005; sampled, the indices of the squeal indicator within 0.02."""
    from brakesqueal.uq import run_uq, uq_summary

    data = tomllib.loads(EXAMPLE.read_text(encoding="utf-8"))
    data["samples"]["n"] = 1 << 15
    mc = uq_summary(run_uq(data, n_resamples=100).dataset)
    ref = mc["quantities"]["max_real"]
    for kw in ({"degree": 6}, {"degree": 10, "sparse": True}):
        sur = fit_study_pce(data, runs=256, **kw)
        s = sur.summary()
        assert sur.runs == 256 and sur.left_out == 0 and s["loo_error"] < 0.01
        for kind in ("first", "total"):
            for nm, v in ref[kind].items():
                assert abs(s[kind][nm] - v) < 0.01, (kw, kind, nm, s[kind][nm], v)
        assert abs(s["p_squeal"] - mc["p_squeal"]["value"]) < 0.005, (s["p_squeal"], mc["p_squeal"])
        # the squeal indicator's indices from a Saltelli design on the surrogate (its own draws, seed 0)
        ind = sur.surrogate.indicator_indices(0.0, n=1 << 14)
        sq = mc["quantities"]["squeal"]
        for kind in ("first", "total"):
            got = getattr(ind, kind)
            for i, nm in enumerate(sur.surrogate.names):
                assert abs(got[i] - sq[kind][nm]) < 0.02, (kw, "squeal", kind, nm, got[i], sq[kind][nm])
    assert 0.1 < mc["p_squeal"]["value"] < 0.9  # not a trivial probability


@pytest.mark.parametrize("kwargs, words", [
    ({"degree": 0}, "degree must be an integer in [1, 20]; got 0"),
    ({"degree": 21}, "degree must be an integer in [1, 20]"),
    ({"degree": 6, "n": 100}, "runs: 100 are too few for degree 6 in 3 inputs (84 basis terms)"),
    ({"q": 0.0}, "q must be in (0, 1]"),
    ({"y": "nan"}, "outputs must be finite"),
    ({"y": "short"}, "outputs must have one value per run (64)"),
    ({"x": "missing"}, "inputs must have exactly the distributions' names"),
    ({"sparse": True, "n": 4}, "runs: 4 are too few for a sparse fit"),
    ({"x": "repeated"}, "do not determine"),
])
def test_bad_input_is_one_line(kwargs, words):
    n = kwargs.pop("n", 64)
    x = pce_design(ISH_DISTS, max(n, 2), seed=0)
    if kwargs.pop("x", None) == "missing":
        x = {"x0": x["x0"], "x1": x["x1"]}
    y: object = ishigami(x) if "x2" in x else np.zeros(n)
    yk = kwargs.pop("y", None)
    if yk == "nan":
        y = np.where(np.arange(n) == 3, np.nan, ishigami(x))
    elif yk == "short":
        y = ishigami(x)[:-1]
    if words == "do not determine":  # 40 distinct points repeated: enough rows, too few distinct for 35 terms
        x = {k: np.tile(v[:30], 4) for k, v in pce_design(ISH_DISTS, 32, seed=0).items()}
        y = ishigami(x)
        kwargs["degree"] = 4
    with pytest.raises(ParameterError) as e:
        fit_pce(x, y, ISH_DISTS, **kwargs)
    msg = str(e.value)
    assert "\n" not in msg and words in msg, msg


def test_study_surrogate_bad_options(tmp_path):
    data = tomllib.loads(EXAMPLE.read_text(encoding="utf-8"))
    for kw, words in (({"quantity": "frequency"}, "quantity must be one of max_real, margin"),
                      ({"runs": 5}, "runs must be in [10, 65536]"),
                      ({"runs": 16, "degree": 4}, "runs: 16 are too few for degree 4")):
        with pytest.raises(ParameterError) as e:
            fit_study_pce(data, **kw)
        assert "\n" not in str(e.value) and words in str(e.value), str(e.value)


MINIMAL = """\
model = "minimal"
[distributions]
mu = { uniform = [0.2, 0.8] }
d = { uniform = [0.5, 10.0] }
[samples]
n = 1024
seed = 3
"""


def test_cli_surrogate_beside_monte_carlo(tmp_path, capsys):
    pytest.importorskip("xarray")
    import json

    from brakesqueal.cli import main

    f = tmp_path / "m.toml"
    f.write_text(MINIMAL, encoding="utf-8")
    out = tmp_path / "r.nc"
    assert main(["uq", str(f), "--surrogate", "pce", "--degree", "5", "--sparse", "--surrogate-runs", "128",
                 "--format", "json", "--out", str(out), "--no-progress"]) == 0
    s = json.loads(capsys.readouterr().out)
    sur = s["surrogate"]
    assert sur["method"] == "pce-omp" and sur["runs"] == 128 and sur["degree"] == 5 and sur["quantity"] == "max_real"
    assert 0 <= sur["loo_error"] < 0.05 and sur["terms"] <= sur["candidates"] == 21
    mc = s["quantities"]["max_real"]
    for kind in ("first", "total"):
        for nm in ("mu", "d"):  # beside the Monte Carlo indices: the same within the Monte Carlo interval + 0.02
            lo, hi = mc[f"{kind}_ci"][nm]
            assert lo - 0.02 <= sur[kind][nm] <= hi + 0.02, (kind, nm, sur[kind][nm], lo, hi)
    assert abs(sur["p_squeal"] - s["p_squeal"]["value"]) < 0.03
    import xarray as xr

    with xr.open_dataset(out) as ds:
        np.testing.assert_allclose(ds["surrogate_first"].values, [sur["first"][n] for n in ("mu", "d")])
        assert ds.attrs["surrogate_loo_error"] == pytest.approx(sur["loo_error"])
    assert main(["uq", str(f), "--surrogate", "pce", "--degree", "3", "--no-progress"]) == 0
    text = capsys.readouterr().out
    assert "surrogate of max_real (pce-ols, degree 3, 10 of 10 terms, 256 runs, 0 left out, leave-one-out error" in text


@pytest.mark.parametrize("args, words", [
    (["--degree", "0"], "--degree must be in [1, 20]; got 0"),
    (["--surrogate-runs", "5"], "--surrogate-runs must be in [10, 65536]"),
    (["--degree", "9", "--surrogate-runs", "64"], "--surrogate-runs 64 is too few for --degree 9 in 2 inputs"),
])
def test_cli_surrogate_bad_options(tmp_path, capsys, args, words):
    from brakesqueal.cli import main

    f = tmp_path / "m.toml"
    f.write_text(MINIMAL, encoding="utf-8")
    assert main(["uq", str(f), "--surrogate", "pce", *args, "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and "\n" not in err, err


@pytest.mark.slow
def test_surrogates_of_the_onset_l1_and_amplitude_reproduce_direct_computations(tmp_path):
    """The expensive nonlinear quantities (issue 27, item 3): l1 with the pads' true rates and the cycles' amplitude
    coefficient at the squeal onset along Omega, over mu1, mu2 of paper-fig3.  The surrogate from 64 runs predicts
    fresh points computed directly (critical speed, then ``hopf_points`` along Omega: the Hopf normal form there),
    and its indices respect the model's symmetry between the two pads (equal first-order indices)."""
    from brakesqueal import Axis, hopf_points, resolve_space
    from brakesqueal.uq import fit_study_pce

    study = {"name": "onset", "preset": "paper-fig3", "parameters": {},
             "distributions": {"mu1": {"uniform": [0.4, 0.6]}, "mu2": {"uniform": [0.4, 0.6]}},
             "samples": {"n": 64, "seed": 3}}
    l1 = fit_study_pce(study, runs=64, degree=3, quantity="onset_l1")
    amp = fit_study_pce(study, runs=64, degree=3, quantity="onset_amplitude")
    assert l1.left_out == 0 and amp.left_out == 0
    s = l1.summary()
    assert "p_subcritical" in s and "p_squeal" not in s and s["p_subcritical"] == 0.0  # supercritical onsets here
    assert amp.summary()["p_squeal"] is None
    for fit in (l1, amp):
        f = fit.summary()["first"]
        assert f["mu1"] == pytest.approx(f["mu2"], abs=0.02)
    rng = np.random.default_rng(11)
    for m1, m2 in rng.uniform(0.42, 0.58, size=(3, 2)):
        space = resolve_space(None, "paper-fig3", None, [f"mu1={float(m1)!r}", f"mu2={float(m2)!r}"])
        onset = next(h for h in hopf_points(space, Axis("Omega", 1.0, 1e5, 2, True))
                     if h.hopf is not None and h.direction == "destabilizing")
        x = {"mu1": np.array([m1]), "mu2": np.array([m2])}
        assert float(l1.surrogate(x)[0]) == pytest.approx(onset.hopf.l1, rel=1e-3)
        direct = float(np.linalg.norm(onset.hopf.amplitude_coefficients[:2]))
        assert float(amp.surrogate(x)[0]) == pytest.approx(direct, rel=1e-3)


def test_onset_surrogates_refuse_a_matrix_model_in_one_line(tmp_path):
    import scipy.io

    from brakesqueal.errors import ParameterError
    from brakesqueal.model.matrices import import_matrices, write_matrix_model
    from brakesqueal.uq import fit_study_pce

    rng = np.random.default_rng(0)
    mat = tmp_path / "m.mat"
    scipy.io.savemat(mat, {"M": np.eye(2), "D": 0.1 * np.eye(2), "K": np.diag([1.0, 2.0]) + 0.1 * rng.random((2, 2))})
    spec = import_matrices([str(mat)], {"M": "M", "D": "s*D", "K": "K"}, parameters={"Omega": 1.0, "s": 1.0})
    write_matrix_model(spec, str(tmp_path / "m.toml"))
    study = {"name": "fe", "model": str(tmp_path / "m.toml"), "parameters": {},
             "distributions": {"s": {"uniform": [0.5, 1.5]}}, "samples": {"n": 16, "seed": 1}}
    with pytest.raises(ParameterError, match="onset_l1.*coefficient matrices"):
        fit_study_pce(study, runs=16, degree=2, quantity="onset_l1")
