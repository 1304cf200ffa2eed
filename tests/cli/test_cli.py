"""The command line as a user runs it: output schemas, cache behaviour and one-line errors (exit 2)."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from brakesqueal import linearize
from brakesqueal.model import get_preset


def run(*args: str, cache: Path, extra_env: dict | None = None) -> subprocess.CompletedProcess:
    env = {**os.environ, "BRAKESQUEAL_CACHE_DIR": str(cache), **(extra_env or {})}
    return subprocess.run([sys.executable, "-m", "brakesqueal", *args], capture_output=True, text=True, env=env)


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("cache")


def test_linearize_json_schema_and_values(cache):
    res = run("linearize", "--preset", "paper-fig2", "--set", "mu=0.4", "--set", "k_ip=inf", "--format", "json",
              cache=cache)  # fmt: skip
    assert res.returncode == 0, res.stderr
    data = json.loads(res.stdout)
    assert {"model", "parameters", "coords", "q0", "q_m0", "M", "D", "K", "eigenvalues", "verdict"} <= set(data)
    assert data["q_m0"] == data["q0"]  # the old key is kept as an alias for one release
    assert data["parameters"]["k_ip1"] == "inf" and data["parameters"]["N0"] == pytest.approx(1800 / 0.4)
    lm = linearize(get_preset("paper-fig2").resolve({"mu": 0.4, "k_ip": math.inf}))
    for key in "MDK":
        assert np.allclose(data[key], getattr(lm, key), rtol=1e-15)
    lam = np.array([complex(a, b) for a, b in data["eigenvalues"]])
    assert np.allclose(lam, lm.eigenvalues, rtol=1e-12)
    assert all(math.isfinite(v) for row in data["K"] for v in row)


def test_linearize_from_toml_file(tmp_path, cache):
    f = tmp_path / "p.toml"
    f.write_text('preset = "paper-fig3"\n[parameters]\nmu1 = 0.7\nmu2 = 0.3\nk_ip = "inf"\n')
    res = run("linearize", "--params", str(f), "--format", "json", cache=cache)
    assert res.returncode == 0, res.stderr
    p = json.loads(res.stdout)["parameters"]
    assert p["mu1"] * p["h10"] == pytest.approx(p["mu2"] * p["h20"])  # eq. (57)
    assert p["Theta"] == pytest.approx(0.16 + 0.32 / 0.045 * (p["h10"] - p["h20"]) ** 2)  # eq. (63)


@pytest.mark.slow
def test_cache_is_written_where_told_and_bypassed_on_request(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    assert run("linearize", cache=a).returncode == 0
    files = list(a.rglob("model.py"))
    assert len(files) == 1 and "def residuals" in files[0].read_text()
    assert run("linearize", "--no-cache", cache=b).returncode == 0
    assert not b.exists() or not any(b.rglob("*.py"))
    # a warm run loads the cached code without importing the computer-algebra systems
    code = ("import sys; from brakesqueal.cli import main; main(['linearize']); "
            "print('CAS', 'sympy' in sys.modules or 'symengine' in sys.modules)")  # fmt: skip
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env={**os.environ, "BRAKESQUEAL_CACHE_DIR": str(a)})  # fmt: skip
    assert out.stdout.strip().endswith("CAS False"), out.stdout[-200:] + out.stderr


@pytest.mark.parametrize("fmt", ["text", "latex", "json"])
@pytest.mark.parametrize("case", ["general", "symmetric", "asymmetric-friction", "minimal"])
def test_derive_prints_each_case(case, fmt, cache):
    res = run("derive", "--case", case, "--format", fmt, cache=cache)
    assert res.returncode == 0, res.stderr
    if fmt == "json":
        data = json.loads(res.stdout)
        assert data["case"] == case and len(data["D"]) == 2 and len(data["D"][0]) == 2
        # the printed entries parse back to the library's closed form
        from brakesqueal.symbolic.linearize import closed_form

        cf = closed_form(case)
        parsed = sp.sympify(data["K"][1][0], locals=cf.symbols)
        assert sp.simplify(parsed - cf.K[1, 0]) == 0
    elif fmt == "latex":
        assert r"\bar{\mathbf{D}}_m" in res.stdout and r"\left[" in res.stdout
    else:
        assert "Dbar[1,2] = Omega*Phi" in res.stdout


BAD = [
    (["linearize", "--set", "mu=-0.2"], "mu1"),
    (["linearize", "--set", "mu=nan"], "nan"),
    (["linearize", "--set", "k_ip=0"], "k_ip"),
    (["linearize", "--preset", "paper-fig3", "--set", "Omega=0"], "Omega"),
    (["linearize", "--set", "r=-1"], "'r'"),
    (["linearize", "--set", "Theta=0"], "Theta"),
    (["linearize", "--set", "N0=-1"], "N0"),
    (["linearize", "--set", "kip=3"], "did you mean 'k_ip'"),
    (["linearize", "--preset", "minimal-model", "--set", "k_ip=1e8"], "k_ip"),
    (["linearize", "--set", "bogus=1"], "bogus"),
    (["linearize", "--set", "mu"], "NAME=VALUE"),
    (["linearize", "--set", "mu=__import__('os')"], "mu"),
    (["linearize", "--preset", "nope"], "nope"),
    (["linearize", "--params", "/does/not/exist.toml"], "exist.toml"),
    (["derive", "--case", "weird"], "weird"),
    (["linearize", "--format", "xml"], "xml"),
]


@pytest.mark.parametrize("args,needle", BAD, ids=[" ".join(a[1:]) for a, _ in BAD])
def test_bad_input_gives_one_line_and_exit_2(args, needle, cache):
    res = run(*args, cache=cache)
    assert res.returncode == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1, res.stderr
    assert needle in lines[0] and "Traceback" not in res.stderr
    assert res.stdout == ""


def test_invalid_toml_names_file_and_position(tmp_path, cache):
    f = tmp_path / "bad.toml"
    f.write_text("[parameters\nmu = 1\n")
    res = run("linearize", "--params", str(f), cache=cache)
    assert res.returncode == 2 and "bad.toml" in res.stderr and "line" in res.stderr


def test_negative_thickness_sum_is_rejected(tmp_path, cache):
    from brakesqueal.model.io import parameters_to_toml

    text = parameters_to_toml(get_preset("paper-fig2").resolve())
    assert "h10 = 0.01" in text
    f = tmp_path / "p.toml"
    f.write_text(text.replace("h10 = 0.01", "h10 = -0.02"))
    res = run("linearize", "--params", str(f), cache=cache)
    assert res.returncode == 2 and "h10" in res.stderr and "h20" in res.stderr


@pytest.mark.slow
def test_bench_derive_script_prints_one_json_array_with_the_required_keys(cache):
    script = Path(__file__).resolve().parents[2] / "benchmarks" / "bench_derive.py"
    res = subprocess.run([sys.executable, str(script), "--no-baseline"], capture_output=True, text=True,
                         env={**os.environ, "BRAKESQUEAL_CACHE_DIR": str(cache)}, timeout=600)
    assert res.returncode == 0, res.stderr
    data = json.loads(res.stdout.strip().splitlines()[-1])
    assert {"metric", "value", "unit", "baseline", "ratio"} <= set(data[0])
    assert data[0]["unit"] == "s" and 0 < data[0]["value"] < 60 and data[0]["baseline"] is None
    kron = data[1]
    assert "Kronecker" in kron["metric"] and kron["ratio"] == pytest.approx(kron["baseline"] / kron["value"])
