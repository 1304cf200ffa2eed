"""Stability maps, crossings and critical speeds of built models through the unified routes (``--model``).

References: eigenvalues of ``linearize`` (exact compiled Jacobians) point by
point, the classic negative-slope threshold of the belt model, the exact
closed-form route of the paper's presets, and bisection on eigenvalues.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from brakesqueal import critical_speeds, crossings
from brakesqueal import linearize
from brakesqueal import Axis, stability_map
from brakesqueal.model import ParameterSpace, get_model, model_to_toml, resolve_space


@pytest.mark.slow
def test_minimal_model_critical_speeds_equal_the_paper_preset():
    """The model 'minimal' and the paper model's preset 'minimal-model' are the same physics: same crossings."""
    built = critical_speeds(resolve_space("minimal"), 1.0, 1e5)
    exact = critical_speeds(ParameterSpace.from_preset("minimal-model", {"mu": 0.5, "N0": 3600}), 1.0, 1e5)
    assert built.crossings and built.complete and "exact" in built.method
    assert [d for _, d in built.crossings] == [d for _, d in exact.crossings]
    for (a, _), (b, _) in zip(built.crossings, exact.crossings):
        assert math.isclose(a, b, rel_tol=1e-9)


def test_belt_crossing_is_the_negative_slope_threshold():
    spec = get_model("belt")
    r = crossings(resolve_space("belt"), Axis("slope", 0.0, 0.02))
    threshold = spec.parameters["d_ip"] / spec.parameters["N0"]
    assert "numeric" in r.method and not r.exhaustive
    assert len(r.crossings) == 1 and r.crossings[0][1] == "destabilizing"
    assert math.isclose(r.crossings[0][0], threshold, rel_tol=1e-10)


@pytest.mark.slow
def test_built_model_map_agrees_with_pointwise_linearization():
    space = resolve_space("six-dof")
    x, y = Axis("k_c", 1e8, 1e10, 7, log=True), Axis("mu1", 0.3, 0.7, 5)
    ds = stability_map(space, x, y).data
    assert ds["max_real"].dims == ("mu1", "k_c") and ds.attrs["model"] == "six-dof"
    assert "per point" in ds.attrs["method"]
    assert np.array_equal(ds["stable"].values, (ds["max_real"].values < 0))
    for j in (0, 2, 4):
        for i in (0, 3, 6):
            kc, mu = float(ds["k_c"][i]), float(ds["mu1"][j])
            lm = linearize(space.resolve({"k_c": kc, "mu1": mu}))
            assert math.isclose(float(ds["max_real"][j, i]), lm.max_real, rel_tol=1e-8, abs_tol=1e-9)
            expected = 0 if abs(mu - 0.5) < 1e-12 else 1  # mu1 != mu2 breaks eq. (49): non-trivial silent motion
            assert int(ds["status"][j, i]) == expected


@pytest.mark.slow
def test_built_model_simulation_matches_the_linear_growth():
    from brakesqueal.model.options import resolve_parameters
    from brakesqueal import simulate

    lm = linearize(resolve_parameters("belt", sets={"slope": 0.2}))
    tr = simulate(resolve_parameters("belt", sets={"slope": 0.2}), 0.5, perturbation=[1e-6], rtol=1e-10)
    s = tr.summary
    assert tr.status == "finished"
    assert abs(s.growth_rate - lm.max_real) <= 0.02 * abs(lm.max_real)
    assert abs(s.frequency_hz - abs(lm.eigenvalues[0].imag) / (2 * math.pi)) <= 1e-3 * s.frequency_hz


def _cli(*args, tmp_path):
    env = {**os.environ, "MPLBACKEND": "Agg"}
    return subprocess.run([sys.executable, "-m", "brakesqueal", *args], capture_output=True, text=True, env=env,
                          cwd=tmp_path)  # fmt: skip


@pytest.mark.slow
def test_cli_accepts_model_files(tmp_path):
    f = tmp_path / "belt.toml"
    f.write_text(model_to_toml(get_model("belt")))
    res = _cli("critical-speed", "--model", str(f), "--range", "1:100", "--format", "json", tmp_path=tmp_path)
    assert res.returncode == 0, res.stderr
    data = json.loads(res.stdout)
    assert set(data) >= {"parameter", "crossings", "Omega_crit", "exhaustive"}
    assert data["exhaustive"] is False and data["Omega_crit_certain"] is False  # grid search: never certain
    res = _cli("map", "--model", "belt", "--x", "slope=0:0.02:5", "--y", "d_ip=0.1:1:4", "--out", "m.nc",
               tmp_path=tmp_path)  # fmt: skip
    assert res.returncode == 0 and (tmp_path / "m.nc").exists(), res.stderr
    res = _cli("simulate", "--model", "belt", "--t-end", "0.05", "--format", "json", tmp_path=tmp_path)
    assert res.returncode == 0 and json.loads(res.stdout)["status"] == "finished", res.stderr


@pytest.mark.parametrize(
    "args,needle",
    [
        (["map", "--model", "belt", "--x", "bogus=0:1:3", "--y", "m=1:2:3", "--out", "x.nc"], "bogus"),
        (["critical-speed", "--model", "belt", "--preset", "paper-fig2"], "paper-fig2"),
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
        ("six-dof", Axis("k_ip2", 1e5, 1e10, 25, log=True), Axis("d1", 0.0, 100.0, 21)),
        ("paper-2dof", Axis("k_ip1", 1e5, 1e10, 40, log=True), Axis("k1", 1e6, 1e7, 15)),
    ],
)
def test_verdict_only_maps_equal_full_maps(model, x, y):
    """``eigen=False`` leaves max_real/frequency out and gives the same certified verdicts and statuses."""
    space = resolve_space(model)
    ref = stability_map(space, x, y, eigen=True).data
    fast = stability_map(space, x, y, eigen=False).data
    assert "max_real" not in fast and "frequency" not in fast
    assert ref["stable"].values.any() and not ref["stable"].values.all(), "the map must contain a boundary"
    np.testing.assert_array_equal(ref["status"].values, fast["status"].values)
    np.testing.assert_array_equal(ref["stable"].values, fast["stable"].values)
    assert np.mean(ref["status"].values <= 1) > 0.99


@pytest.mark.parametrize("model,xname,yname,yv,lo,hi", [("paper-2dof", "k_ip1", "k1", 6e6, 1e5, 1e10),
                                                         ("eight-dof", "k_c", "k_cn", 5e7, 1e8, 1e10)])
@pytest.mark.slow
def test_verdicts_near_the_boundary(model, xname, yname, yv, lo, hi):
    """Points placed just off a boundary (found by bisection on eigenvalues): certified verdicts are never wrong."""
    from scipy.optimize import brentq

    space = resolve_space(model)

    def mr(v):
        return linearize(space.resolve({xname: v, yname: yv})).max_real

    grid = np.geomspace(lo, hi, 60)
    vals = np.array([mr(v) for v in grid])
    i = int(np.flatnonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))[0])
    root = brentq(mr, grid[i], grid[i + 1], xtol=1e-6)
    for rel in (1e-4, 1e-6):
        pts = Axis(xname, root * (1 - rel), root * (1 + rel), 2, True)
        ds = stability_map(space, pts, Axis(yname, yv, yv * 1.02, 2)).data.sel({yname: yv})
        for v in ds[xname].values:
            code = int(ds["status"].sel({xname: v}))
            if code == 5:
                continue  # undecided is allowed, a wrong verdict is not
            assert bool(ds["stable"].sel({xname: v})) == (mr(float(v)) < 0)
