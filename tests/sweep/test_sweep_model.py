"""Sweeps over built models (``model = ...`` in a study file)."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from brakesqueal import linearize
from brakesqueal.model import get_model, model_to_toml


def linearize_model(spec, overrides=None):
    """The linear model of ``spec`` at its default values with ``overrides``."""
    return linearize(spec.get_preset().resolve(dict(overrides or {})))
from brakesqueal.errors import ParameterError
from brakesqueal.sweep import sweep


@pytest.mark.slow
def test_model_study_matches_pointwise_linearization(tmp_path):
    ds = sweep({"model": "six-dof", "parameters": {"d_c": 40.0},
                "axes": {"k_c": "1e8:1e10:5:log", "mu1": "0.4:0.6:3"},
                "compute": {"quantities": ["stable", "max_real", "frequency", "margin"]}})  # fmt: skip
    assert ds["max_real"].dims == ("k_c", "mu1")
    for i in range(5):
        for j in range(3):
            kc, mu = float(ds["k_c"][i]), float(ds["mu1"][j])
            lm = linearize_model(get_model("six-dof"), {"d_c": 40.0, "k_c": kc, "mu1": mu})
            lam = lm.eigenvalues[0]
            assert np.isclose(float(ds["max_real"][i, j]), lam.real, rtol=1e-8, atol=1e-9)
            assert np.isclose(float(ds["frequency"][i, j]), abs(lam.imag) / (2 * np.pi), rtol=1e-10)
            assert bool(ds["stable"][i, j]) == (lam.real < 0)
            assert int(ds["status"][i, j]) == (0 if abs(mu - 0.5) < 1e-12 else 1)  # mu1 != mu2: non-trivial


def test_model_study_from_file_with_samples_and_store(tmp_path):
    model = tmp_path / "belt.toml"
    model.write_text(model_to_toml(get_model("belt")))
    study = tmp_path / "s.toml"
    study.write_text('model = "belt.toml"\n[samples]\nmethod = "lhs"\nn = 40\nseed = 3\n'
                     '[samples.ranges]\nslope = "0:0.02"\n[compute]\nquantities = ["stable", "max_real"]\n')
    ds = sweep(str(study), store=str(tmp_path / "s.zarr"))
    slope = ds["slope"].values
    v = get_model("belt").parameters
    expected = -(v["d_ip"] - v["N0"] * slope) / (2 * v["m"])  # classic negative-slope growth rate
    assert np.allclose(ds["max_real"].values, expected, rtol=1e-9, atol=1e-12)
    assert np.array_equal(ds["stable"].values, slope < v["d_ip"] / v["N0"])


@pytest.mark.parametrize(
    "data,key",
    [
        ({"model": "belt", "preset": "paper-fig2", "axes": {"slope": "0:1:3"}}, "preset"),
        ({"model": "no-such", "axes": {"slope": "0:1:3"}}, "model"),
        ({"model": "belt", "axes": {"bogus": "0:1:3"}}, "axes.bogus"),
        ({"model": "belt", "parameters": {"m": -1.0}, "axes": {"slope": "0:1:3"}}, "parameters.m"),
        ({"model": "belt", "axes": {"slope": "0:1:3"}, "compute": {"quantities": ["critical_speed"]}},
         "compute.quantities"),
    ],
)
def test_model_study_errors_name_the_key(data, key):
    with pytest.raises(ParameterError, match=key.replace(".", r"\.")):
        sweep(data)


def test_model_study_cli_exit_code(tmp_path):
    study = tmp_path / "bad.toml"
    study.write_text('model = "belt"\ntied = { m = "2*k_ip" }\n[axes]\nslope = "0:1:3"\n')
    res = subprocess.run([sys.executable, "-m", "brakesqueal", "sweep", str(study)], capture_output=True, text=True,
                         env={**os.environ}, cwd=tmp_path)  # fmt: skip
    assert res.returncode == 2 and len(res.stderr.strip().splitlines()) == 1 and "tied" in res.stderr
