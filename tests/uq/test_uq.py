"""Squeal as a probability (issue 27, items 1-2): distributions in study files, ``brakesqueal uq``.

The Sobol' indices of the library are checked against independent brute-force estimates written here (plain
Monte Carlo pick-freeze with numpy's generator, not the library's QMC design or estimators) on the minimal and the
six-dof model, the two backends against each other, P(squeal) against direct Monte Carlo, resume against an
uninterrupted run, and the bad inputs of a study file.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("xarray")
pytest.importorskip("zarr")

from brakesqueal.cli import main  # noqa: E402
from brakesqueal.errors import ParameterError  # noqa: E402
from brakesqueal.sweep import load_study, sweep  # noqa: E402
from brakesqueal.sweep.compute import ChunkSpec, compute_chunk  # noqa: E402
from brakesqueal.uq import (Distribution, probability_interval, run_uq, saltelli_design, sobol_estimate,  # noqa: E402
                            uq_summary)

MINIMAL = """\
model = "minimal"
[distributions]
mu = {{ uniform = [0.2, 0.8] }}
d = {{ uniform = [0.5, 10.0] }}
[samples]
n = {n}
seed = 3
"""

#: six-dof with equal friction on both faces (a trivial silent motion: the compiled grid routes), three inputs
SIX = """\
model = "six-dof"
[parameters]
mu1 = 0.25
mu2 = 0.25
[distributions]
k1 = {{ uniform = [2e6, 1e7] }}
d1 = {{ truncnormal = [5.0, 3.0, 0.0, 10.0] }}
d_ip = {{ uniform = [0.0, 50.0] }}
[samples]
n = {n}
seed = 5
"""


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


# ---------------------------------------------------------------- independent brute force
def _evaluator(text: str):
    """f(values: dict name -> array) -> (max_real, squeal, decided) through the project's evaluator."""
    st = load_study(json.loads(json.dumps(_as_dict(text))))
    spec = ChunkSpec.from_study(st)

    def f(values):
        r = compute_chunk(spec, values)
        decided = np.isin(r["status"], [0, 1])
        return r["max_real"], (decided & ~r["stable"]).astype(float), decided
    return f


def _as_dict(text: str) -> dict:
    import tomllib

    return tomllib.loads(text)


def _draw(dists: dict, n: int, rng) -> dict:
    """Plain Monte Carlo draws (numpy generator, inverse CDF of scipy's frozen distribution)."""
    return {k: d.frozen().ppf(rng.random(n)) for k, d in dists.items()}


def brute_force(text: str, n: int, seed: int, batches: int = 20) -> dict:
    """First-order (pick-freeze: Cov(f(X), f(X with all but x_i redrawn)) / Var) and total (Jansen with x_i redrawn)
    indices by plain Monte Carlo, with standard errors from batch means."""
    st = load_study(_as_dict(text))
    dists = {r.name: r.distribution for r in st.ranges}
    names = list(dists)
    f = _evaluator(text)
    rng = np.random.default_rng(seed)
    x, x2 = _draw(dists, n, rng), _draw(dists, n, rng)
    y = f(x)
    assert y[2].all()
    est = {}
    for qi, q in enumerate(("max_real", "squeal")):
        est[q] = {"first": {}, "total": {}, "first_se": {}, "total_se": {}}
    for nm in names:
        keep = {k: (x[k] if k == nm else x2[k]) for k in names}  # x_i frozen, the others redrawn
        redraw = {k: (x2[k] if k == nm else x[k]) for k in names}  # x_i redrawn
        yk, yr = f(keep), f(redraw)
        assert yk[2].all() and yr[2].all()
        for qi, q in enumerate(("max_real", "squeal")):
            a, b, c = y[qi], yk[qi], yr[qi]
            fo, to = [], []
            for s in np.array_split(np.arange(n), batches):
                v = np.var(a[s])
                fo.append(np.mean((a[s] - a[s].mean()) * (b[s] - b[s].mean())) / v)
                to.append(0.5 * np.mean((a[s] - c[s]) ** 2) / v)
            v = np.var(a)
            est[q]["first"][nm] = np.mean((a - a.mean()) * (b - b.mean())) / v
            est[q]["total"][nm] = 0.5 * np.mean((a - c) ** 2) / v
            est[q]["first_se"][nm] = np.std(fo, ddof=1) / math.sqrt(batches)
            est[q]["total_se"][nm] = np.std(to, ddof=1) / math.sqrt(batches)
    return est


def assert_agree(summary: dict, bf: dict) -> None:
    """Every brute-force index within the library's interval (widened by 3 brute-force standard errors)."""
    for q in ("max_real", "squeal"):
        got = summary["quantities"][q]
        for kind in ("first", "total"):
            for nm, ref in bf[q][kind].items():
                lo, hi = got[f"{kind}_ci"][nm]
                se = bf[q][f"{kind}_se"][nm]
                assert lo - 3 * se <= ref <= hi + 3 * se, (q, kind, nm, ref, se, got[kind][nm], lo, hi)
                assert lo <= got[kind][nm] <= hi


@pytest.mark.slow
def test_indices_agree_with_brute_force_minimal(tmp_path):
    f = write(tmp_path / "m.toml", MINIMAL.format(n=4096))
    s = uq_summary(run_uq(f).dataset)
    assert s["no_verdict"] == 0 and 0.2 < s["p_squeal"]["value"] < 0.9
    assert_agree(s, brute_force(MINIMAL.format(n=4096), 40000, seed=11))


@pytest.mark.slow
def test_indices_agree_with_brute_force_six_dof(tmp_path):
    f = write(tmp_path / "s.toml", SIX.format(n=2048))
    s = uq_summary(run_uq(f).dataset)
    assert 0.1 < s["p_squeal"]["value"] < 0.9
    assert_agree(s, brute_force(SIX.format(n=2048), 30000, seed=12))


# ---------------------------------------------------------------- estimators alone (analytic reference)
def test_estimator_on_ishigami_function():
    """Known indices of the Ishigami function (a = 7, b = 0.1): S = (0.3139, 0.4424, 0), ST = (0.5576, 0.4424,
    0.2437); both backends contain them in their intervals, and agree with each other."""
    pytest.importorskip("SALib")
    u = saltelli_design(8192, 3, 1)
    x = -math.pi + 2 * math.pi * u
    y = np.sin(x[..., 0]) + 7 * np.sin(x[..., 1]) ** 2 + 0.1 * x[..., 2] ** 4 * np.sin(x[..., 0])
    first_ref, total_ref = np.array([0.3139, 0.4424, 0.0]), np.array([0.5576, 0.4424, 0.2437])
    res = {b: sobol_estimate(y[0], y[1], y[2:], backend=b, seed=4) for b in ("scipy", "salib")}
    for e in res.values():
        assert np.all((e.first_ci[:, 0] <= first_ref + 1e-3) & (first_ref - 1e-3 <= e.first_ci[:, 1]))
        assert np.all((e.total_ci[:, 0] <= total_ref + 1e-3) & (total_ref - 1e-3 <= e.total_ci[:, 1]))
    a, b = res["scipy"], res["salib"]
    assert np.all(np.abs(a.first - b.first) <= np.minimum(a.first_ci[:, 1] - a.first_ci[:, 0],
                                                          b.first_ci[:, 1] - b.first_ci[:, 0]))
    assert np.all(np.abs(a.total - b.total) <= np.minimum(a.total_ci[:, 1] - a.total_ci[:, 0],
                                                          b.total_ci[:, 1] - b.total_ci[:, 0]))
    # a constant output has no indices (never 0/0 reported as a number)
    c = sobol_estimate(np.ones(8), np.ones(8), np.ones((2, 8)))
    assert np.isnan(c.first).all() and np.isnan(c.total_ci).all()


def test_design_is_saltelli_and_seeded():
    u = saltelli_design(64, 3, 9)
    assert u.shape == (5, 64, 3) and np.all((u > 0) & (u < 1))
    np.testing.assert_array_equal(u, saltelli_design(64, 3, 9))
    assert not np.array_equal(u, saltelli_design(64, 3, 10))
    for i in range(3):  # AB_i: A with column i from B
        expect = u[0].copy()
        expect[:, i] = u[1][:, i]
        np.testing.assert_array_equal(u[2 + i], expect)
    with pytest.raises(ParameterError, match="power of two"):
        saltelli_design(100, 3, 0)


def test_wilson_interval():
    p, lo, hi = probability_interval(30, 100)
    assert p == 0.3 and lo == pytest.approx(0.2189, abs=1e-4) and hi == pytest.approx(0.3958, abs=1e-4)
    assert probability_interval(0, 50)[1] == 0.0
    with pytest.raises(ParameterError, match="0 <= k <= m"):
        probability_interval(5, 3)


# ---------------------------------------------------------------- backends, P(squeal), resume
def test_scipy_and_salib_agree_on_the_minimal_model(tmp_path):
    pytest.importorskip("SALib")
    f = write(tmp_path / "m.toml", MINIMAL.format(n=1024))
    a = uq_summary(run_uq(f).dataset)
    b = uq_summary(run_uq(f, backend="salib").dataset)
    assert b["backend"] == "salib"
    for q in ("max_real", "squeal", "frequency"):
        for kind in ("first", "total"):
            for nm in ("mu", "d"):
                va, vb = a["quantities"][q][kind][nm], b["quantities"][q][kind][nm]
                la, ha = a["quantities"][q][f"{kind}_ci"][nm]
                lb, hb = b["quantities"][q][f"{kind}_ci"][nm]
                assert la <= vb <= ha and lb <= va <= hb, (q, kind, nm)


def test_p_squeal_agrees_with_direct_monte_carlo(tmp_path):
    f = write(tmp_path / "m.toml", MINIMAL.format(n=2048))
    s = uq_summary(run_uq(f).dataset)
    p, (lo, hi) = s["p_squeal"]["value"], s["p_squeal"]["ci"]
    assert s["p_squeal"]["with_verdict"] == 4096 and lo < p < hi
    # direct Monte Carlo: a plain random sample study of the same distributions, through `sweep`
    mc_text = MINIMAL.format(n=60000).replace("seed = 3", 'seed = 99\nmethod = "random"')
    ds = sweep(_as_dict(mc_text))
    status, stable = ds["status"].values, ds["stable"].values
    assert np.isin(status, [0, 1]).all()
    p_mc = float((~stable).mean())
    se = math.sqrt(p_mc * (1 - p_mc) / stable.size)
    assert lo - 3 * se <= p_mc <= hi + 3 * se, (p_mc, se, lo, hi)
    # the sweep drew from the distributions
    assert ds["mu"].values.min() >= 0.2 and ds["mu"].values.max() <= 0.8
    assert abs(ds["d"].values.mean() - 5.25) < 0.05


def test_killed_run_resumes_with_identical_indices(tmp_path, monkeypatch):
    import brakesqueal.sweep.runner as runner

    text = MINIMAL.format(n=512) + "[execution]\nchunk_points = 256\n"
    f = write(tmp_path / "m.toml", text)
    store = tmp_path / "m.uq.zarr"
    ref = run_uq(f).dataset  # in memory, uninterrupted
    calls = []
    orig = runner.compute_chunk

    def dying(spec, coords):
        if len(calls) == 3:
            raise KeyboardInterrupt  # killed after three chunks
        calls.append(1)
        return orig(spec, coords)

    monkeypatch.setattr(runner, "compute_chunk", dying)
    with pytest.raises(KeyboardInterrupt):
        run_uq(f, store=store)
    monkeypatch.undo()
    run = run_uq(f, store=store)
    assert (run.computed, run.reused) == (5, 3)  # 4 blocks of 512 points in chunks of 256
    for v in ("first", "total", "first_ci", "total_ci", "p_squeal", "p_squeal_ci", "max_real"):
        np.testing.assert_array_equal(run.dataset[v].values, ref[v].values)
    again = run_uq(f, store=store)
    assert (again.computed, again.reused) == (0, 8)


# ---------------------------------------------------------------- the command
def test_cli_json(tmp_path, capsys):
    f = write(tmp_path / "m.toml", MINIMAL.format(n=256))
    out, plot = tmp_path / "r.nc", tmp_path / "r.png"
    assert main(["uq", str(f), "--format", "json", "--out", str(out), "--plot", str(plot), "--no-progress"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert set(s["quantities"]) == {"max_real", "squeal", "frequency"}
    assert s["evaluations"] == 256 * 4 and s["no_verdict"] == 0
    for q, v in s["quantities"].items():
        assert set(v["first"]) == set(v["total"]) == {"mu", "d"}
        for nm in ("mu", "d"):
            lo, hi = v["first_ci"][nm]
            tlo, thi = v["total_ci"][nm]
            assert lo <= v["first"][nm] <= hi and tlo <= v["total"][nm] <= thi
            assert lo <= thi  # first <= total within the intervals
            assert -0.2 < v["first"][nm] < 1.2 and -0.05 < v["total"][nm] < 1.5
        assert sum(v["first"].values()) < 1.2
    p = s["p_squeal"]
    assert p["ci"][0] <= p["value"] <= p["ci"][1] and p["squealing"] == round(p["value"] * p["with_verdict"])
    import xarray as xr

    with xr.open_dataset(out) as ds:
        first = s["quantities"]["max_real"]["first"]
        np.testing.assert_allclose(ds["first"].values[0], [first[n] for n in ("mu", "d")])
        assert float(ds["p_squeal"]) == p["value"]
    assert plot.stat().st_size > 10000
    assert main(["uq", str(f)]) == 0
    text = capsys.readouterr().out
    assert "P(squeal) = " in text and "first" in text and "total" in text


def test_points_without_a_verdict_are_counted_not_stable(tmp_path, monkeypatch):
    """Points the evaluator leaves undecided are counted, left out of the indices and bound P(squeal)."""
    import brakesqueal.analysis.quantities as quantities

    orig = quantities.evaluate_block

    def some_undecided(engine, space, pts, names, **kw):
        out = orig(engine, space, pts, names, **kw)
        k = np.arange(out["status"].size) % 17 == 0
        out["status"][k], out["stable"][k], out["max_real"][k] = 5, False, np.nan
        return out

    monkeypatch.setattr(quantities, "evaluate_block", some_undecided)
    f = write(tmp_path / "m.toml", MINIMAL.format(n=256))
    s = uq_summary(run_uq(f).dataset)
    n_und = 4 * int(np.sum(np.arange(256) % 17 == 0))  # four chunks (blocks A, B, AB_1, AB_2) of 256 points
    assert s["no_verdict"] == n_und and s["status_counts"]["undecided"] == n_und
    assert s["quantities"]["max_real"]["rows"] < 256
    p = s["p_squeal"]
    assert p["without_verdict"] > 0 and p["with_verdict"] + p["without_verdict"] == 512
    assert p["bounds"][0] < p["value"] < p["bounds"][1]


# ---------------------------------------------------------------- bad input
BASE = 'preset = "minimal-model"\n{extra}\n[samples]\nn = {n}\nseed = 1\n'


@pytest.mark.parametrize("dist, n, key, words", [
    ("mu = { normal = [0.45, 0.05] }", 64, "distributions.mu.normal", ["(-inf, inf)", "[0, inf)", "truncnormal"]),
    ("mu = { uniform = [-0.1, 0.5] }", 64, "distributions.mu.uniform", ["mu1", "[0, inf)", "-0.1"]),
    ("k_t = { lognormal = [1e7, 0.1] }\nk1 = { normal = [6e6, 1e5] }", 64, "distributions.k1.normal", ["[0, inf)"]),
    ("mu = { gamma = [1, 2] }", 64, "distributions.mu.gamma", ["unknown distribution", "uniform = [lo, hi]",
                                                                 "beta = [a, b, lo, hi]"]),
    ("mu = { uniform = [0.3, 0.5] }", 0, "samples.n", ["positive integer", "got 0"]),
    ("mu = { uniform = [0.3, 0.5] }", -4, "samples.n", ["positive integer"]),
    ("mu1 = { uniform = [0.3, 0.5] }", 64, "distributions.mu1", ["tied", "replace its tie"]),
    ("muu = { uniform = [0.3, 0.5] }", 64, "distributions.muu", ["unknown parameter", "did you mean 'mu'"]),
    ("mu = { uniform = [0.5, 0.3] }", 64, "distributions.mu.uniform", ["lo < hi"]),
    ("mu = { truncnormal = [0.4, 0.0, 0.3, 0.5] }", 64, "distributions.mu.truncnormal", ["sd must be in (0, inf)"]),
    ("mu = { beta = [2, 2, 0.3] }", 64, "distributions.mu.beta", ["4 numbers"]),
    ("mu = 0.4", 64, "distributions.mu", ["one distribution"]),
])
def test_bad_input_is_one_line(tmp_path, capsys, dist, n, key, words):
    f = write(tmp_path / "bad.toml", BASE.format(extra="[distributions]\n" + dist, n=n))
    assert main(["uq", str(f), "--format", "json"]) == 2
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert captured.out == "" and len(err.splitlines()) == 1, err
    assert f"study file '{f}'" in err and f"key '{key}'" in err, err
    for w in words:
        assert w in err, (w, err)


def test_a_replaced_tie_may_have_a_distribution(tmp_path):
    text = BASE.format(extra="[parameters]\nmu1 = 0.4\n[distributions]\nmu1 = { uniform = [0.3, 0.5] }", n=8)
    st = load_study(write(tmp_path / "ok.toml", text))
    assert st.ranges[0].distribution == Distribution("mu1", "uniform", (0.3, 0.5))


def test_uq_needs_distributions_and_tie_violations_are_refused(tmp_path, capsys):
    plain = BASE.format(extra="", n=8).replace("[samples]", "[samples]\nranges = { mu = \"0.3:0.5\" }")
    f = write(tmp_path / "plain.toml", plain)
    assert main(["uq", str(f)]) == 2
    assert "key 'samples.ranges.mu'" in capsys.readouterr().err
    # mu2 = 1 - mu1 carries mu1 > 1 out of mu2's range: found on the support's extremes, named
    text = BASE.format(extra='[tied]\nmu2 = "1 - mu1"\n[distributions]\nmu1 = { uniform = [0.5, 1.5] }', n=8)
    text = text.replace("minimal-model", "paper-fig3")
    g = write(tmp_path / "tie.toml", text)
    with pytest.raises(ParameterError, match=r"key 'distributions.mu1.uniform'.*mu2.*\[0, inf\)"):
        load_study(g)


def test_distribution_changes_the_study_hash(tmp_path):
    a = load_study(_as_dict(MINIMAL.format(n=64)))
    b = load_study(_as_dict(MINIMAL.format(n=64).replace("[0.5, 10.0]", "[0.5, 10.5]")))
    assert a.hash() != b.hash()
    s = a.samples()
    assert set(s) == {"mu", "d"} and s["mu"].min() >= 0.2 and s["mu"].max() <= 0.8


@pytest.mark.slow
def test_dask_workers_give_the_in_memory_indices(tmp_path):
    f = write(tmp_path / "m.toml", MINIMAL.format(n=512))
    ref = run_uq(f).dataset
    run = run_uq(f, workers=2)
    assert run.store == str((tmp_path / "m.uq.zarr").resolve()) and run.computed == 4
    for v in ("first", "total", "first_ci", "total_ci", "p_squeal", "p_squeal_ci"):
        np.testing.assert_array_equal(run.dataset[v].values, ref[v].values)


def test_sweep_draws_sobol_points_from_distributions():
    text = MINIMAL.format(n=1000).replace("seed = 3", 'seed = 3\nmethod = "sobol"')
    a, b = load_study(_as_dict(text)), load_study(_as_dict(text))
    sa = a.samples()
    np.testing.assert_array_equal(sa["d"], b.samples()["d"])
    assert sa["mu"].shape == (1000,) and 0.2 <= sa["mu"].min() and sa["mu"].max() <= 0.8
    # low discrepancy: the mean of a uniform is much closer than plain Monte Carlo's standard error 0.17/sqrt(1000)
    assert abs(sa["mu"].mean() - 0.5) < 0.002
    assert a.hash() != load_study(_as_dict(text.replace('"sobol"', '"lhs"'))).hash()


@pytest.mark.parametrize("args, words", [
    (["--confidence", "1.5"], ["--confidence", "(0, 1)"]),
    (["--resamples", "3"], ["--resamples", "[10, 100000]"]),
    (["--out", "x.txt"], ["--out", ".nc"]),
    (["--workers", "0"], ["--workers", "positive integer"]),
])
def test_bad_options_are_one_line(tmp_path, capsys, args, words):
    f = write(tmp_path / "m.toml", MINIMAL.format(n=8))
    assert main(["uq", str(f), *[a if a != "x.txt" else str(tmp_path / a) for a in args]]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and all(w in err for w in words), err
