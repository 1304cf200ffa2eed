"""``brakesqueal import`` and every linear command on the model file it writes (the issue's command forms).

References: a dense QZ of the companion pencil of NLEVP ``disk_brake100`` assembled in the test from
``scipy.io.loadmat`` (independent of brakesqueal's reader and coefficient grammar).
"""

from __future__ import annotations

import json
import math
import os
import shutil

import numpy as np
import pytest
import scipy.io
import scipy.linalg

from brakesqueal.cli import main

DB100 = os.path.join(os.path.dirname(__file__), "..", "..", "src", "brakesqueal", "data", "fe",
                     "nlevp-disk-brake-100", "disk_brake100.mat")


def cli(capsys, *args: str) -> tuple[int, str, str]:
    rc = main(list(args))
    out = capsys.readouterr()
    return rc, out.out, out.err


def _qz(w: float, s: float = 1.0) -> np.ndarray:
    d = scipy.io.loadmat(DB100)
    r = {k: np.asarray(d[k], dtype=float) for k in ("M", "D1", "DR", "DG", "K1", "KR")}
    n = 100
    D, K = r["D1"] + s * r["DR"] / w + w * r["DG"], r["K1"] + s * r["KR"]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-K, -D]])
    B = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), r["M"]]])
    return scipy.linalg.eig(A, B, right=False)


@pytest.fixture()
def model(tmp_path, capsys, monkeypatch):
    """The issue's import form, in a fresh folder: ``model.toml`` beside ``disk_brake100.mat``."""
    shutil.copy(DB100, tmp_path / "disk_brake100.mat")
    monkeypatch.chdir(tmp_path)
    rc, out, err = cli(capsys, "import", "disk_brake100.mat", "--coefficient", "M=M", "--coefficient",
                       "D=D1 + DR/Omega + Omega*DG", "--coefficient", "K=K1 + KR", "--out", "model.toml")
    assert rc == 0, err
    assert "100 DOF" in out and "model.toml" in out
    return tmp_path / "model.toml"


def test_import_then_linearize_json_lists_every_eigenvalue(model, capsys):
    rc, out, err = cli(capsys, "linearize", "--model", "model.toml", "--set", "Omega=4*pi", "--format", "json")
    assert rc == 0, err
    d = json.loads(out)
    lam = np.array([complex(a, b) for a, b in d["eigenvalues"]])
    ref = _qz(4 * math.pi)
    assert lam.size == 200
    for z in ref:  # every eigenvalue of the dense QZ is listed (QZ's own accuracy, see test_matrix_models)
        assert np.min(np.abs(lam - z)) <= 1e-8 * abs(z)
    assert d["verdict"]["status"] == "unstable" and d["verdict"]["carrier"] == "structure"


def test_the_model_file_moves_with_its_matrices(model, tmp_path, capsys):
    """Paths in the model file are relative to it: the pair can be moved and the file read from elsewhere."""
    dst = tmp_path / "moved"
    dst.mkdir()
    shutil.move(str(model), dst / "model.toml")
    shutil.move(str(tmp_path / "disk_brake100.mat"), dst / "disk_brake100.mat")
    rc, out, err = cli(capsys, "linearize", "--model", str(dst / "model.toml"), "--set", "Omega=2")
    assert rc == 0, err
    assert "Model 'disk_brake100' (100 DOF, given by coefficient matrices)" in out


def test_eigen_map_crossings_modes_take_the_model(model, tmp_path, capsys):
    rc, out, err = cli(capsys, "eigen", "--model", "model.toml", "--set", "Omega=2*pi", "--format", "json")
    assert rc == 0, err
    e = json.loads(out)
    assert len(e["modes"]) == 200 and e["verdict"]["status"] == "unstable"
    rc, out, err = cli(capsys, "import", "disk_brake100.mat", "-c", "M=M", "-c", "D=D1 + s*DR/Omega + Omega*DG",
                       "-c", "K=K1 + s*KR", "-c", "s=1", "--parameter", "Omega=2*pi", "--out", "m2.toml")
    assert rc == 0, err
    rc, out, err = cli(capsys, "map", "--model", "m2.toml", "--x", "Omega=6.28:25.1:3", "--y", "s=0:1:3",
                       "--out", "m.nc")
    assert rc == 0, err
    import xarray as xr

    with xr.open_dataset(tmp_path / "m.nc") as ds:
        for i, s in enumerate(ds["s"].values):
            for j, w in enumerate(ds["Omega"].values):
                assert bool(ds["stable"].values[i, j]) == (_qz(float(w), float(s)).real.max() < 0)
    rc, out, err = cli(capsys, "modes", "--model", "m2.toml", "--along", "s=0:0.2", "--num", "5", "--format", "json")
    assert rc == 0, err
    tracks = json.loads(out)
    assert tracks["parameter"] == "s" and tracks["model"] == "disk_brake100"


@pytest.mark.slow
def test_crossings_and_critical_speed_take_the_model(model, capsys):
    rc, out, err = cli(capsys, "import", "disk_brake100.mat", "-c", "M=M", "-c", "D=D1 + s*DR/Omega + Omega*DG",
                       "-c", "K=K1 + s*KR", "-c", "s=1", "--out", "m2.toml")
    assert rc == 0, err
    rc, out, err = cli(capsys, "crossings", "--model", "m2.toml", "--set", "Omega=2*pi", "--along", "s=0:0.3",
                       "--format", "json")
    assert rc == 0, err
    r = json.loads(out)
    (c,) = r["crossings"]
    assert _qz(2 * math.pi, c["value"] * 0.999).real.max() < 0 < _qz(2 * math.pi, c["value"] * 1.001).real.max()
    rc, out, err = cli(capsys, "critical-speed", "--model", "m2.toml", "--set", "s=1", "--range", "1:100",
                       "--format", "json")
    assert rc == 0, err
    cs = json.loads(out)
    assert cs["stable_at_start"] is False  # the published brake squeals at every speed of the range (dense scan)
    assert all(_qz(w).real.max() > 0 for w in (1.0, 10.0, 100.0))


def test_sweep_takes_the_model(model, tmp_path, capsys):
    study = tmp_path / "study.toml"
    study.write_text('name = "fe"\nmodel = "model.toml"\n[axes]\nOmega = { values = [2, 20] }\n'
                     '[compute]\nquantities = ["stable", "max_real"]\n[output]\nstore = "fe.zarr"\n')
    rc, out, err = cli(capsys, "sweep", str(study))
    assert rc == 0, err
    import xarray as xr

    ds = xr.open_zarr(tmp_path / "fe.zarr")
    for k, w in enumerate(ds["Omega"].values):
        ref = _qz(float(w)).real.max()
        assert float(ds["max_real"].values[k]) == pytest.approx(ref, rel=1e-6)
        assert bool(ds["stable"].values[k]) == (ref < 0)


@pytest.mark.parametrize("args, words", [
    (["import", "nothere.mat", "-c", "M=M", "-c", "D=D1", "-c", "K=K1", "--out", "x.toml"], "nothere.mat"),
    (["import", "disk_brake100.mat", "-c", "M=M", "-c", "D=D1", "--out", "x.toml"], "--coefficient for K"),
    (["import", "disk_brake100.mat", "-c", "M=M", "-c", "D=D1", "-c", "K=K1*KR", "--out", "x.toml"],
     "product of two matrices"),
    (["import", "disk_brake100.mat", "-c", "M=M", "-c", "D=D1", "-c", "K=K9", "--out", "x.toml"],
     "multiplies no matrix (matrices: D1, DG, DR, K1, KR, M)"),
    (["import", "disk_brake100.mat", "-c", "M=M", "-c", "D=D1", "-c", "K=K1", "--out", "x.txt"], ".toml"),
    (["import", "disk_brake100.mat", "-c", "M=M", "-c", "D=D1", "-c", "K=K1", "--format", "xyz", "--out", "x.toml"],
     "xyz"),
    (["import", "disk_brake100.mat", "-c", "M=M", "-c", "D=D1", "-c", "K=K1", "--out", "disk_brake100.mat"],
     "--out"),
    (["hopf", "--model", "model.toml", "--along", "Omega=1:2"], "coefficient matrices"),
    (["simulate", "--model", "model.toml"], "coefficient matrices"),
    (["cycles", "--model", "model.toml", "--along", "Omega=1:2"], "coefficient matrices"),
    (["export", "--model", "model.toml", "--to", "python", "--out", "x.py"], "coefficient matrices"),
    (["linearize", "--model", "model.toml", "--set", "Omega=-1"], "Omega"),
    (["linearize", "--model", "disk_brake4669"], "dense eigenvalues are limited"),
])
def test_bad_input_is_one_line_exit_2(model, capsys, args, words):
    rc, out, err = cli(capsys, *args)
    assert rc == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("brakesqueal: error: ") and "Traceback" not in err, err
    assert words in lines[0]


def test_box_counts_the_unstable_modes_of_a_dense_qz(capsys):
    w = 2 * math.pi
    rc, out, err = cli(capsys, "box", "--model", "disk_brake100", "--set", f"Omega={w!r}", "--re=-0.05:1",
                       "--freq", "0:0.2", "--format", "json", "--no-progress")
    assert rc == 0, err
    r = json.loads(out)
    ref = _qz(w)
    f = ref.imag / (2 * math.pi)
    inside = ref[(ref.real >= -0.05) & (ref.real <= 1) & (f >= 0) & (f <= 0.2)]
    assert r["complete"] and len(r["eigenvalues"]) == inside.size
    assert r["unstable"] == int(np.sum(inside.real > 0)) == 1
    for e in r["eigenvalues"]:
        z = complex(e["re"], e["im"])
        assert np.min(np.abs(inside - z)) <= max(e["bound"], 1e-8 * abs(z))


def test_reduce_writes_a_model_every_command_takes(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    rc, out, err = cli(capsys, "reduce", "--model", "disk_brake100", "--along", "Omega=2*pi:8*pi:3", "--re=-0.05:1",
                       "--freq", "0:0.2", "--out", "r.toml", "--format", "json", "--no-progress")
    assert rc == 0, err
    r = json.loads(out)
    assert r["dimension"] < 100 and r["max_rel_error"] < 1e-4 and r["reliable"]
    # the checks lie between the samples (at a sample the error would be the projection's rounding only)
    assert all(c["Omega"] not in r["samples"] for c in r["checks"]) and len(r["checks"]) == 2
    assert (tmp_path / "r.mat").exists()
    w = 9.0  # not a sample: the reduced model's box eigenvalues against the full dense QZ
    rc, out, err = cli(capsys, "linearize", "--model", "r.toml", "--set", f"Omega={w}", "--format", "json")
    assert rc == 0, err
    lam = np.array([complex(a, b) for a, b in json.loads(out)["eigenvalues"]])
    ref = _qz(w)
    f = ref.imag / (2 * math.pi)
    for z in ref[(ref.real >= -0.05) & (f >= 0) & (f <= 0.2)]:
        assert np.min(np.abs(lam - z)) <= 1e-4 * abs(z)


def test_a_basis_with_the_left_eigenvectors_is_more_accurate(tmp_path, capsys, monkeypatch):
    """The default basis (right and left eigenvectors) against --right-only at the same dimension: the checks'
    eigenvalue errors are products of the right and left vectors' distances from the basis, not first order
    (measured at r = 64: 300 to 490 times smaller; at equal small r the right vectors alone are better)."""
    monkeypatch.chdir(tmp_path)
    runs = {}
    for flag in ([], ["--right-only"]):
        rc, out, err = cli(capsys, "reduce", "--model", "disk_brake100", "--along", "Omega=2*pi:8*pi:3", "--re=-0.05:1",
                           "--freq", "0:0.2", "--dim", "64", "--out", "r.toml", "--format", "json", "--no-progress",
                           *flag)
        assert rc == 0, err
        runs[bool(flag)] = json.loads(out)
    both, right = runs[False], runs[True]
    assert both["basis"] == "right and left eigenvectors" and right["basis"] == "right eigenvectors"
    assert both["dimension"] == right["dimension"] == 64
    assert both["max_rel_error"] < 1e-2 * right["max_rel_error"], (both["max_rel_error"], right["max_rel_error"])
    assert max(c["max_re_error"] for c in both["checks"]) < 1e-2 * max(c["max_re_error"] for c in right["checks"])


def test_reduce_says_when_the_reduced_real_parts_are_too_coarse(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    rc, out, err = cli(capsys, "reduce", "--model", "disk_brake100", "--along", "Omega=2*pi:8*pi:3", "--re=-0.05:1",
                       "--freq", "0:0.2", "--dim", "4", "--out", "r.toml", "--no-progress")
    assert rc == 0, err
    assert "4 DOF" in out and "verdicts may differ from the full model's" in err


@pytest.mark.parametrize("args, words", [
    (["box", "--preset", "paper-fig2", "--re=-1:1", "--freq", "0:2000"], "coefficient matrices"),
    (["box", "--model", "disk_brake100", "--re", "1:-1", "--freq", "0:1"], "--re needs LO < HI"),
    (["box", "--model", "disk_brake100", "--re=-1:1", "--freq", "-5:1"], "freq"),
    (["reduce", "--model", "disk_brake100", "--along", "Omega=1:2:2", "--re=-1:1", "--freq", "0:1", "--out", "r.txt"],
     ".toml"),
])
def test_box_and_reduce_bad_input_is_one_line(capsys, args, words):
    rc, out, err = cli(capsys, *args)
    lines = err.strip().splitlines()
    assert rc == 2 and len(lines) == 1 and "Traceback" not in err, err
    assert words in lines[0]


def test_list_models_names_the_fe_benchmarks(capsys):
    rc, out, err = cli(capsys, "list", "models", "--format", "json")
    assert rc == 0, err
    rows = {r["name"]: r for r in json.loads(out)}
    assert rows["disk_brake100"]["dof"] == 100 and rows["disk_brake4669"]["kind"] == "matrices"
    from brakesqueal.model import get_model

    assert get_model("disk_brake100").n == rows["disk_brake100"]["dof"]
