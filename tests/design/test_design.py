"""Robust design (issue 27, item 5): ``brakesqueal.design`` and ``brakesqueal design``.

The certified windows are checked against an independent route (the exact crossings of the Hurwitz polynomials
along ``k_ip``, ``brakesqueal crossings``: the paper's points B and A at ``mu = 0.5``), the certified statements
against dense sampling with the verdict dispatcher, the optimiser against the baseline, and the bad inputs of a
design study through the CLI.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import brakesqueal as bs
from brakesqueal.analysis.points import evaluate
from brakesqueal.cli import main
from brakesqueal.design import load_design, robust_design, run_design, stable_windows
from brakesqueal.errors import ParameterError

OMEGA = "Omega=50.26548245743669"
EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "study-design-kip.toml"

STUDY = """\
preset = "paper-fig2"
[parameters]
Omega = 50.26548245743669
[distributions]
mu = {{ uniform = [0.35, 0.55] }}
[samples]
n = {n}
seed = {seed}
[design]
variables = {{ k_ip = [1e5, 1e8] }}
objective = "{objective}"
tolerance = 0.05
maxiter = {maxiter}
popsize = 6
"""


def _space(*sets: str) -> bs.ParameterSpace:
    return bs.resolve_space(None, "paper-fig2", None, [OMEGA, *sets])


def _crossings(mu: float) -> list[float]:
    c = bs.crossings(_space(f"mu={mu!r}"), bs.parse_axis("k_ip=1e5:1e10:10:log"))
    return [x for x, _ in c.crossings]


def _study(tmp_path: Path, *, n: int = 256, seed: int = 7, objective: str = "p_squeal", maxiter: int = 6,
           text: str | None = None, windows: bool = True) -> Path:
    f = tmp_path / "design.toml"
    f.write_text((text if text is not None else STUDY.format(n=n, seed=seed, objective=objective, maxiter=maxiter))
                 + ("" if windows else "windows = false\n"))
    return f


def test_kip_window_at_mu_05_is_between_the_papers_points_b_and_a():
    """The certified window of k_ip at mu = 0.5 is [B, A] of Fig. 2, as the exact crossings place them."""
    sp = _space("mu=0.5")
    eng = bs.engine(sp)
    (w,) = stable_windows(eng, sp, "k_ip", (1e5, 1e10))
    b, a = _crossings(0.5)
    assert 2.2e5 < b < 2.4e5 and 1.8e6 < a < 1.9e6  # the paper's B and A (docs/stability.md)
    np.testing.assert_allclose(w, (b, a), rtol=1e-6)
    assert b <= w[0] and w[1] <= a * (1 + 1e-12)  # certified: never wider than the true window
    k = np.geomspace(w[0], w[1], 2001)
    assert np.asarray(evaluate(eng, sp, {"k_ip": k}).stable).all()
    outside = np.concatenate([np.geomspace(1e5, b * 0.999, 200), np.geomspace(a * 1.001, 1e10, 200)])
    assert not np.asarray(evaluate(eng, sp, {"k_ip": outside}).stable).any()


def test_robust_window_over_a_mu_box_is_certified_and_matches_the_crossings():
    """Over every mu in [0.35, 0.55] the window is [B(0.35), A(0.55)] (exact crossings) and sampling agrees."""
    sp = _space()
    eng = bs.engine(sp)
    (w,) = stable_windows(eng, sp, "k_ip", (1e5, 1e8), box={"mu": (0.35, 0.55)})
    np.testing.assert_allclose(w, (_crossings(0.35)[0], _crossings(0.55)[1]), rtol=1e-6)
    rng = np.random.default_rng(5)
    k = np.exp(rng.uniform(np.log(w[0]), np.log(w[1]), 20000))
    mu = rng.uniform(0.35, 0.55, 20000)
    assert np.asarray(evaluate(eng, sp, {"k_ip": k, "mu": mu}).stable).all()


def test_design_lowers_p_squeal_and_its_certified_statement_holds(tmp_path):
    res = run_design(_study(tmp_path))
    pb, po = res.p_squeal["baseline"], res.p_squeal["optimum"]
    assert res.baseline == {"k_ip": 1e8}
    assert pb["value"] > 0.6 and po["value"] == 0.0
    assert po["ci"][1] < pb["ci"][0]  # the Wilson intervals are apart
    # certified: every point of mu in [0.35, 0.55] x k_ip (1 +- 5 %) at the optimum is stable; dense sampling agrees
    assert res.certified["optimum"]["verdict"] == "stable" and res.margin["optimum"] == 1.0
    assert res.uncertain == {"mu": (0.35, 0.55)}
    k0 = res.optimum["k_ip"]
    rng = np.random.default_rng(11)
    sp = _space()
    v = evaluate(bs.engine(sp), sp, {"k_ip": rng.uniform(0.95 * k0, 1.05 * k0, 20000),
                                     "mu": rng.uniform(0.35, 0.55, 20000)})
    assert np.asarray(v.stable).all()
    # the baseline is certified unstable, with a witness the dispatcher confirms
    cb = res.certified["baseline"]
    assert cb["verdict"] == "unstable" and res.margin["baseline"] == 0.0
    wv = evaluate(bs.engine(sp), sp, {"k_ip": cb["witness"]["k_ip"], "mu": cb["witness"]["mu"]})
    assert not np.asarray(wv.stable).any() and np.asarray(wv.max_real).max() > 0
    # the optimum is inside the robust window, which the exact crossings bound
    (w,) = res.robust_windows["k_ip"]
    assert w[0] <= k0 / 1.05 and 1.05 * k0 <= w[1]
    assert _crossings(0.35)[0] <= w[0] and w[1] <= _crossings(0.55)[1] * (1 + 1e-12)


def test_objective_is_deterministic_with_a_seed(tmp_path):
    f = _study(tmp_path, maxiter=3, windows=False)
    r1, r2 = run_design(f), run_design(f)
    assert r1.optimum == r2.optimum and r1.p_squeal == r2.p_squeal
    np.testing.assert_array_equal(r1.history, r2.history)
    np.testing.assert_array_equal(r1.objective_values, r2.objective_values)
    # common random numbers: the same design gets the same P(squeal) whatever else is evaluated
    sp = _space()
    eng = bs.engine(sp)
    from brakesqueal.design import squeal_counts

    draws = load_design(f).study.samples()
    one = squeal_counts(eng, sp, {"k_ip": np.array([3e7])}, draws)
    many = squeal_counts(eng, sp, {"k_ip": np.array([1e6, 3e7, 1e8])}, draws)
    assert one.squealing[0] == many.squealing[1]
    # the library draws exactly what the study file draws (the same n, seed and method)
    from brakesqueal.uq import Distribution

    mu = Distribution("mu", "uniform", (0.35, 0.55))
    lib = robust_design(eng, sp, {"k_ip": (1e5, 1e8)}, distributions={"mu": mu}, n=256, seed=7, tolerance=0.05,
                        maxiter=3, popsize=6, windows=False)
    assert lib.optimum == r1.optimum and lib.p_squeal == r1.p_squeal
    f8 = tmp_path / "seed8.toml"
    f8.write_text(f.read_text().replace("seed = 7", "seed = 8"))
    other = run_design(f8)
    assert not np.array_equal(load_design(f8).study.samples()["mu"], draws["mu"])
    assert not np.array_equal(other.history, r1.history)


def test_margin_objective_maximises_the_certified_scale():
    sp = _space()
    eng = bs.engine(sp)
    r = robust_design(eng, sp, {"k_ip": (1e5, 1e8)}, objective="margin", uncertain={"mu": (0.4, 0.5)},
                      max_scale=8.0, maxiter=5, popsize=6, windows=False)
    t = r.margin["optimum"]
    assert t is not None and 1.5 < t < 8.0 and r.margin["baseline"] == 0.0  # boxes past mu < 0 are not stable
    # the certified scaled box (mu = 0.45 +- 0.05 t) is stable by sampling too, and a 5 % larger one is not
    mu = np.linspace(0.45 - 0.05 * t, 0.45 + 0.05 * t, 20001)
    k0 = r.optimum["k_ip"]
    assert np.asarray(evaluate(eng, sp, {"k_ip": np.full(mu.size, k0), "mu": mu}).stable).all()
    big = np.linspace(max(0.45 - 0.0525 * t, 1e-6), 0.45 + 0.0525 * t, 4001)
    assert not np.asarray(evaluate(eng, sp, {"k_ip": np.full(big.size, k0), "mu": big}).stable).all()
    # the certified margin at a design inside the window but off the optimum is smaller
    off = robust_design(eng, sp, {"k_ip": (1.5e6, 1.6e6)}, objective="margin", uncertain={"mu": (0.4, 0.5)},
                        max_scale=8.0, maxiter=2, popsize=4, windows=False)
    assert off.margin["optimum"] is not None and off.margin["optimum"] < t


def test_two_variables_and_the_json_and_netcdf_outputs(tmp_path, capsys):
    text = STUDY.format(n=128, seed=3, objective="p_squeal", maxiter=3).replace(
        "variables = { k_ip = [1e5, 1e8] }", "variables = { k_ip = [1e5, 1e8], d1 = [1.0, 10.0] }")
    f = _study(tmp_path, text=text, windows=False)
    out = tmp_path / "d.json"
    assert main(["design", str(f), "--format", "json", "--out", str(out), "--no-progress"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert json.loads(out.read_text()) == s
    assert set(s["optimum"]) == {"k_ip", "d1"} and s["scales"] == {"k_ip": "log", "d1": "linear"}
    assert s["p_squeal"]["optimum"]["value"] < s["p_squeal"]["baseline"]["value"]
    nc = tmp_path / "d.nc"
    assert main(["design", str(f), "--out", str(nc), "--no-progress"]) == 0
    assert "optimum: k_ip=" in capsys.readouterr().out
    import xarray as xr

    with xr.open_dataset(nc) as ds:
        assert ds["candidate_x"].shape[1] == 2 and ds["candidate_objective"].size == ds["candidate_x"].shape[0]


@pytest.mark.parametrize("old,new,key,words", [
    ("k_ip = [1e5, 1e8]", "k_ip = [1e8, 1e8]", "design.variables.k_ip", "degenerate"),
    ("k_ip = [1e5, 1e8]", "k_ip = [1e8, 1e5]", "design.variables.k_ip", "lo < hi"),
    ("k_ip = [1e5, 1e8]", "mu1 = [0.1, 0.8]", "design.variables.mu1", "tied"),
    ("k_ip = [1e5, 1e8]", "k_iq = [1e5, 1e8]", "design.variables.k_iq", "unknown parameter"),
    ("k_ip = [1e5, 1e8]", "mu = [0.1, 0.8]", "design.variables.mu", "also in [distributions]"),
    ("k_ip = [1e5, 1e8]", "k_ip = [0, 1e8]", "design.variables.k_ip", "invalid parameter set"),
    ("variables = { k_ip = [1e5, 1e8] }", "variables = {}", "design.variables", "non-empty"),
    ("n = 256", "n = 0", "samples.n", "positive"),
    ('objective = "p_squeal"', 'objective = "cost"', "design.objective", "p_squeal, margin"),
    ("maxiter = 6", "maxiter = 0", "design.maxiter", "integer in [1,"),
    ("tolerance = 0.05", "tolerance = 2", "design.tolerance", "[0, 0.5]"),
    ("tolerance = 0.05", "toleranse = 0.05", "design.toleranse", "unknown key"),
    ("[design]", "[designs]", "designs", "unknown key"),
    ("popsize = 6", "popsize = 6\nwindows = 1", "design.windows", "true or false"),
])
def test_bad_design_study_is_one_line(tmp_path, capsys, old, new, key, words):
    f = _study(tmp_path)
    text = f.read_text()
    assert old in text
    f.write_text(text.replace(old, new))
    assert main(["design", str(f), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    assert f"key '{key}'" in err and words in err, err


def test_missing_design_table_and_bad_api_input(tmp_path, capsys):
    f = _study(tmp_path)
    f.write_text(f.read_text().split("[design]")[0])
    assert main(["design", str(f)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "key 'design'" in err and "missing" in err
    sp = _space()
    eng = bs.engine(sp)
    with pytest.raises(ParameterError, match="zero samples"):
        robust_design(eng, sp, {"k_ip": (1e5, 1e8)}, draws={"mu": np.zeros(0)})
    with pytest.raises(ParameterError, match="'k_ip'.*degenerate"):
        robust_design(eng, sp, {"k_ip": (1e5, 1e5)}, draws={"mu": np.full(4, 0.5)})
    with pytest.raises(ParameterError, match="needs distributions"):
        robust_design(eng, sp, {"k_ip": (1e5, 1e8)})
    with pytest.raises(ParameterError, match="n"):
        robust_design(eng, sp, {"k_ip": (1e5, 1e8)}, n=0)


SIX = """\
model = "six-dof"
[parameters]
mu1 = 0.25
mu2 = 0.25
[distributions]
d1 = { uniform = [0.5, 10.0] }
[samples]
n = 32
seed = 5
[design]
variables = { k1 = [2e6, 1e7] }
maxiter = 1
popsize = 3
"""


def test_model_without_closed_form_optimises_p_squeal_and_refuses_the_margin(tmp_path, capsys):
    """six-dof: P(squeal) is optimised, nothing certified is claimed; the margin objective is one line."""
    f = _study(tmp_path, text=SIX)
    assert main(["design", str(f), "--format", "json", "--no-progress"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["certified"]["optimum"]["verdict"] == "not available" and "closed-form" in s["certified"]["optimum"][
        "reason"]
    assert s["windows"] == {"k1": None} and s["margin"]["optimum"] is None
    assert s["p_squeal"]["optimum"]["with_verdict"] == 32
    f.write_text(SIX + 'objective = "margin"\n')
    assert main(["design", str(f), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err and "closed-form" in err and "key 'design'" in err


def test_example_study_loads():
    ds = load_design(EXAMPLE)
    assert ds.variables == {"k_ip": (1e5, 1e8)} and ds.objective == "p_squeal" and ds.study.n_samples == 1024
