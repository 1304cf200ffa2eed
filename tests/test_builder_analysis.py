"""Stability maps, crossings, critical speeds and simulation of built models (``--model``)."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from brakesqueal.analysis.maps import Axis
from brakesqueal.analysis.space import ParameterSpace
from brakesqueal.analysis.crossings import critical_speeds
from brakesqueal.builder import get_model, linearize_model
from brakesqueal.builder.analysis import ModelSpace, model_critical_speeds, model_crossings, model_stability_map


def test_built_model_critical_speeds_equal_the_exact_2dof_route():
    """Minimal model: bracketing + Brent on eigenvalues vs. exact Hurwitz root isolation of the preset."""
    built = model_critical_speeds(ModelSpace(get_model("minimal")), 1.0, 1e5)
    exact = critical_speeds(ParameterSpace.from_preset("minimal-model", {"mu": 0.5, "N0": 3600}), 1.0, 1e5)
    assert [d for _, d in built.crossings] == [d for _, d in exact.crossings]
    for (a, _), (b, _) in zip(built.crossings, exact.crossings):
        assert math.isclose(a, b, rel_tol=1e-9)


def test_belt_crossing_is_the_negative_slope_threshold():
    spec = get_model("belt")
    r = model_crossings(ModelSpace(spec), Axis("slope", 0.0, 0.02))
    threshold = spec.parameters["d_ip"] / spec.parameters["N0"]
    assert len(r.crossings) == 1 and r.crossings[0][1] == "destabilizing"
    assert math.isclose(r.crossings[0][0], threshold, rel_tol=1e-10)


def test_built_model_map_agrees_with_pointwise_linearization():
    space = ModelSpace(get_model("six-dof"))
    x, y = Axis("k_c", 1e8, 1e10, 7, log=True), Axis("mu1", 0.3, 0.7, 5)
    ds = model_stability_map(space, x, y).data
    assert ds["max_real"].dims == ("mu1", "k_c")
    assert np.array_equal(ds["stable"].values, (ds["max_real"].values < 0))
    for j in (0, 2, 4):
        for i in (0, 3, 6):
            kc, mu = float(ds["k_c"][i]), float(ds["mu1"][j])
            lm = linearize_model(get_model("six-dof"), {"k_c": kc, "mu1": mu})
            assert math.isclose(float(ds["max_real"][j, i]), lm.max_real, rel_tol=1e-8, abs_tol=1e-9)
            expected = 0 if abs(mu - 0.5) < 1e-12 else 1  # mu1 != mu2 breaks eq. (49): non-trivial silent motion
            assert int(ds["status"][j, i]) == expected


def test_built_model_simulation_matches_the_linear_growth():
    from brakesqueal.model.options import resolve_parameters
    from brakesqueal.simulation import simulate

    lm = linearize_model(get_model("belt"), {"slope": 0.2})
    tr = simulate("belt", resolve_parameters("belt", sets={"slope": 0.2}), 0.5, perturbation=[1e-6], rtol=1e-10)
    s = tr.summary
    assert tr.status == "finished"
    assert abs(s.growth_rate - lm.max_real) <= 0.02 * abs(lm.max_real)
    assert abs(s.frequency_hz - abs(lm.eigenvalues[0].imag) / (2 * math.pi)) <= 1e-3 * s.frequency_hz


def _cli(*args, tmp_path):
    env = {**os.environ, "MPLBACKEND": "Agg"}
    return subprocess.run([sys.executable, "-m", "brakesqueal", *args], capture_output=True, text=True, env=env,
                          cwd=tmp_path)  # fmt: skip


def test_cli_accepts_model_files(tmp_path):
    from brakesqueal.builder import model_to_toml

    f = tmp_path / "belt.toml"
    f.write_text(model_to_toml(get_model("belt")))
    res = _cli("critical-speed", "--model", str(f), "--range", "1:100", "--format", "json", tmp_path=tmp_path)
    assert res.returncode == 0, res.stderr
    assert set(json.loads(res.stdout)) >= {"parameter", "crossings", "Omega_crit"}
    res = _cli("map", "--model", "belt", "--x", "slope=0:0.02:5", "--y", "d_ip=0.1:1:4", "--out", "m.nc",
               tmp_path=tmp_path)  # fmt: skip
    assert res.returncode == 0 and (tmp_path / "m.nc").exists(), res.stderr
    res = _cli("simulate", "--model", "belt", "--t-end", "0.05", "--format", "json", tmp_path=tmp_path)
    assert res.returncode == 0 and json.loads(res.stdout)["status"] == "finished", res.stderr


@pytest.mark.parametrize(
    "args,needle",
    [
        (["map", "--model", "belt", "--x", "bogus=0:1:3", "--y", "m=1:2:3", "--out", "x.nc"], "bogus"),
        (["critical-speed", "--model", "belt", "--preset", "paper-fig2"], "--model"),
        (["linearize", "--model", "no-such-model"], "no-such-model"),
        (["linearize", "--model", "six-dof", "--set", "m_p=-1"], "m_p"),
        (["simulate", "--model", "belt", "--t-end", "-1"], "--t-end"),
    ],
)
def test_cli_model_errors_are_one_line(args, needle, tmp_path):
    res = _cli(*args, tmp_path=tmp_path)
    assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1 and needle in res.stderr, res.stderr


@pytest.mark.parametrize(
    "model,x,y",
    [
        ("eight-dof", Axis("k_c", 1e8, 1e10, 31, log=True), Axis("k_cn", 1e6, 1e9, 23, log=True)),
        ("eight-dof", Axis("k_ip1", 1e6, 1e10, 29, log=True), Axis("m_p", 0.1, 2.0, 17)),
        ("six-dof", Axis("k_ip2", 1e5, 1e10, 25, log=True), Axis("d1", 0.0, 100.0, 21)),
        ("six-dof", Axis("N0", 1e3, 2e4, 25, log=True), Axis("d_c", 0.0, 200.0, 21)),
        ("paper-2dof", Axis("k_ip1", 1e5, 1e10, 40, log=True), Axis("k1", 1e6, 1e7, 15)),
    ],
)
def test_routh_classification_equals_eigenvalue_verdicts(model, x, y):
    """The eigenvalue-free fast path (interpolated characteristic polynomial + Routh) vs batched eigenvalues."""
    space = ModelSpace(get_model(model))
    ref = model_stability_map(space, x, y, eigen=True).data
    fast = model_stability_map(space, x, y, eigen=False).data
    if model == "paper-2dof":  # the certified Routh test decides quartics; degree-2n ones of lightly damped
        assert "Routh" in fast.attrs["method"]  # models with n > 2 fall back to eigenvalues (see fastmap)
    assert ref["stable"].values.any() and not ref["stable"].values.all(), "the map must contain a boundary"
    both = (ref["status"].values <= 1) & (fast["status"].values <= 1)
    # certified verdicts of both routes agree wherever both are decided
    assert np.array_equal(ref["stable"].values[both], fast["stable"].values[both])
    assert both.mean() > 0.99
    assert np.array_equal(ref["status"].values >= 2, fast["status"].values >= 2) or \
        set(np.unique(ref["status"].values[~both])) | set(np.unique(fast["status"].values[~both])) <= {5}


@pytest.mark.parametrize("model,xname,yname,yv,lo,hi", [("paper-2dof", "k_ip1", "k1", 6e6, 1e5, 1e10),
                                                         ("eight-dof", "k_c", "k_cn", 5e7, 1e8, 1e10)])
def test_routh_classification_near_the_boundary(model, xname, yname, yv, lo, hi):
    """Points placed just off a boundary (found by bisection on eigenvalues): certified codes are never wrong."""
    from scipy.optimize import brentq

    spec = get_model(model)
    space = ModelSpace(spec)

    def mr(kc):
        return linearize_model(spec, {xname: kc, yname: yv}).max_real

    grid = np.geomspace(lo, hi, 60)
    vals = np.array([mr(v) for v in grid])
    i = int(np.flatnonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))[0])
    root = brentq(mr, grid[i], grid[i + 1], xtol=1e-6)
    pts = np.array([root * (1 - 1e-4), root * (1 + 1e-4)])
    from brakesqueal.builder.fastmap import classify
    from brakesqueal.builder.analysis import _matrices_at_zero, _params, _vectorized
    from brakesqueal.builder.numeric import compile_model

    cm = compile_model(spec)
    vec = _vectorized(cm)

    def mats(xv, yv):
        pp = _params(space, cm, {xname: xv, yname: yv}, xv.size)
        return _matrices_at_zero(space, cm, vec, pp, xv.size)[:3]

    xs = np.concatenate([np.geomspace(lo, hi, 9), pts])
    xs.sort()
    codes = classify(mats, xs, np.array([yv, yv * 1.02]), x_log=True, y_log=True)[0]
    expect = np.array([mr(v) < 0 for v in xs]).astype(np.uint8)
    decided = codes != 2
    assert np.array_equal(codes[decided], expect[decided])
    if model == "paper-2dof":
        assert decided.all()
