"""Parameter studies (issue 6): study files, kernels vs. stability_map, store, resume, corruption, errors."""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np
import pytest

xr = pytest.importorskip("xarray")
pytest.importorskip("zarr")
pytest.importorskip("dask")

from brakesqueal import critical_speeds, stability_map
from brakesqueal.analysis.stability import ParameterSpace, parse_axis  # noqa: E402
from brakesqueal.cli import main  # noqa: E402
from brakesqueal.errors import ParameterError  # noqa: E402
from brakesqueal.sweep import load_study, open_sweep, sweep, sweep_status  # noqa: E402
from brakesqueal.sweep.store import MARKERS  # noqa: E402

EIGEN = ["stable", "margin", "max_real", "frequency"]


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def same_results(a, b) -> None:
    """Identical variables, coordinates and provenance (except the creation time)."""
    xr.testing.assert_identical(a.load().drop_attrs(deep=False), b.load().drop_attrs(deep=False))
    drop = {"created"}
    assert {k: v for k, v in a.attrs.items() if k not in drop} == {k: v for k, v in b.attrs.items() if k not in drop}


# ---------------------------------------------------------------- results vs. the stability kernels
def test_2d_grid_equals_stability_map():
    study = {"preset": "paper-fig2", "axes": {"mu": "0.05:1:23", "k_ip": "1e5:1e10:31:log"},
             "compute": {"quantities": EIGEN}, "execution": {"chunk_points": 200}}
    ds = sweep(study)
    assert ds["stable"].dims == ("mu", "k_ip") and load_study(study).n_chunks > 1
    m = stability_map(ParameterSpace.from_preset("paper-fig2"), parse_axis("k_ip=1e5:1e10:31:log"),
                      parse_axis("mu=0.05:1:23")).data.transpose("mu", "k_ip", ...)
    for v in ("stable", "status"):
        np.testing.assert_array_equal(ds[v].values, m[v].values)
    mr, fr = ds["max_real"].values, ds["frequency"].values
    # the map's compiled quartic roots and the sweep's companion eigenvalues agree to rounding of |λ|
    lam = np.hypot(mr, 2 * np.pi * fr)
    assert np.all(np.abs(mr - m["max_real"].values) <= 1e-12 * lam)
    assert np.all(2 * np.pi * np.abs(fr - m["frequency"].values) <= 1e-12 * lam)
    np.testing.assert_allclose(ds["margin"].values, -mr / np.hypot(mr, 2 * np.pi * fr))
    assert 0.2 < ds["stable"].values.mean() < 0.8


def test_3d_grid_slices_equal_maps_and_verdict_only_is_same():
    om = [20.0, 16 * math.pi, 300.0]
    study = {"preset": "paper-fig2", "axes": {"Omega": {"values": om}, "k_ip": "1e5:1e10:25:log", "mu": "0.05:1:17"},
             "compute": {"quantities": ["stable"]}, "execution": {"chunks": {"Omega": 1, "k_ip": 10}}}
    ds = sweep(study)
    assert list(ds.data_vars) == ["stable", "status"] and ds["stable"].dims == ("Omega", "k_ip", "mu")
    for i, w in enumerate(om):
        m = stability_map(ParameterSpace.from_preset("paper-fig2", {"Omega": w}), parse_axis("k_ip=1e5:1e10:25:log"),
                          parse_axis("mu=0.05:1:17"), eigen=False).data.transpose("k_ip", "mu", ...)
        np.testing.assert_array_equal(ds["stable"].values[i], m["stable"].values)
    full = sweep({**study, "compute": {"quantities": EIGEN}})
    np.testing.assert_array_equal(full["stable"].values, ds["stable"].values)
    # least-stable eigenvalue agrees with the exact verdict away from the boundary
    mr = full["max_real"].values
    clear = np.abs(mr) > 1e-3
    assert np.all((mr[clear] < 0) == full["stable"].values[clear])


def test_invalid_points_flagged_never_stable():
    study = {"preset": "paper-fig2", "axes": {"mu": {"values": [0.0, 0.3, 0.6]}, "k_ip": "1e6:1e9:5:log"},
             "compute": {"quantities": EIGEN}}
    ds = sweep(study)
    assert np.all(ds["status"].values[0] == 4) and not ds["stable"].values[0].any()  # N0 = 1800/0
    assert np.all(np.isnan(ds["max_real"].values[0]))
    assert np.all(ds["status"].values[1:] == 0)


def test_nontrivial_silent_motion_uses_numeric_linearization():
    """mu1 != mu2 tilts the disk; the massless pads then keep their tangential rate (their own real mode).

    At the tilted silent motion each pad's balance gets a rate term ``G_dL ~
    c_ip mu d q2`` and a real mode ``lambda ~ -G_L / G_dL`` of order ``1/(c_ip
    mu d q2)``, positive for one pad: unstable.  ``max_real`` must be that
    eigenvalue, checked here in 60-digit arithmetic from the descriptor
    matrices of ``linearize`` (the QZ eigenvalues of ``LinearModel`` are only
    accurate to ~1e-3 relative for it: the pencil is badly scaled).
    """
    import mpmath

    from brakesqueal import linearize

    base = ParameterSpace.from_preset("paper-fig2").resolve({})
    vals = {k: ("inf" if math.isinf(v) else v) for k, v in base.as_dict().items()}
    study = {"parameters": vals, "axes": {"mu1": {"values": [0.5, 0.55]}, "k_ip1": {"values": [1e6, 1e8]}},
             "compute": {"quantities": EIGEN}}
    ds = sweep(study)
    assert ds["status"].values[0].tolist() == [0, 0] and ds["status"].values[1].tolist() == [1, 1]
    for j, k in enumerate([1e6, 1e8]):
        lm = linearize(base.replace(mu1=0.55, k_ip1=k))
        assert lm.pad_states == ("l1", "l2")
        E, A = lm.descriptor
        with mpmath.workdps(60):
            S = mpmath.inverse(mpmath.matrix(E.tolist())) * mpmath.matrix(A.tolist())
            top = max(mpmath.eig(S, left=False, right=False), key=lambda z: z.real)
        assert float(top.real) > 1e10 and abs(float(top.imag)) < 1e-20 * float(top.real)
        assert not ds["stable"].values[1, j] and lm.max_real > 0
        assert ds["max_real"].values[1, j] == pytest.approx(float(top.real), rel=1e-9)
        assert ds["max_real"].values[1, j] == pytest.approx(lm.max_real, rel=1e-2)


def test_samples_lhs_and_random(tmp_path):
    study = {"preset": "paper-fig2", "samples": {"method": "lhs", "n": 400, "seed": 3,
                                                "ranges": {"k_ip": "1e5:1e10:log", "mu": {"start": 0.05, "stop": 1}}},
             "compute": {"quantities": EIGEN}, "execution": {"chunk_points": 150}}
    ds = sweep(study, store=tmp_path / "s.zarr")
    assert ds["stable"].dims == ("sample",) and ds.sizes["sample"] == 400
    assert set(ds.coords) == {"sample", "k_ip", "mu"}
    k, mu = ds["k_ip"].values, ds["mu"].values
    # Latin hypercube: one sample in each of the 400 strata of every parameter
    assert np.array_equal(np.sort(np.floor((np.log10(k) - 5) / 5 * 400)), np.arange(400))
    assert np.array_equal(np.sort(np.floor((mu - 0.05) / 0.95 * 400)), np.arange(400))
    again = sweep(study)  # in memory, same seed -> same samples and results
    same_results(ds.drop_attrs(), again.drop_attrs())
    space = ParameterSpace.from_preset("paper-fig2")
    for i in (0, 17, 399):
        m = stability_map(space, parse_axis(f"k_ip={k[i]}:{k[i] * 2}:2"), parse_axis(f"mu={mu[i]}:{mu[i] + 0.1}:2"))
        assert bool(m.data["stable"].sel(k_ip=k[i], mu=mu[i])) == bool(ds["stable"].values[i])
    rnd = sweep({**study, "samples": {**study["samples"], "method": "random", "seed": 4}})
    assert not np.allclose(rnd["mu"].values, mu)


@pytest.mark.slow
def test_critical_speed_with_study_tie():
    study = {"preset": "paper-fig3", "parameters": {"k_ip": 1e8}, "tied": {"mu2": "1 - mu1"},
             "axes": {"mu1": {"values": [0.3, 0.5, 0.9]}},
             "compute": {"quantities": ["stable", "critical_speed"], "critical_speed_range": [1, 1e5]}}
    ds = sweep(study)
    assert ds["critical_speed"].values[1] == pytest.approx(35.741, abs=1e-3)  # docs/stability.md, Fig. 3
    for i, m1 in enumerate([0.3, 0.5, 0.9]):
        r = critical_speeds(ParameterSpace.from_preset("paper-fig3", {"mu1": m1, "mu2": 1 - m1, "k_ip": 1e8}))
        want = r.Omega_crit
        got = ds["critical_speed"].values[i]
        assert (math.isnan(got) and want is None) or got == pytest.approx(want, rel=1e-12)


# ---------------------------------------------------------------- store, provenance, resume, corruption
STUDY3 = """\
name = "t3"
preset = "paper-fig2"
[axes]
Omega = {{ values = [20, 50.26548245743669, 100] }}
mu = "0.05:1:12"
k_ip = "1e5:1e10:15:log"
[compute]
quantities = {q}
[execution]
chunk_points = 60
"""


def test_store_provenance_status_and_no_recompute(tmp_path, monkeypatch):
    import brakesqueal
    import brakesqueal.sweep.runner as runner

    f = write(tmp_path / "s.toml", STUDY3.format(q=json.dumps(EIGEN)))
    st = load_study(f)
    assert st.chunks == (1, 4, 15) and st.n_chunks == 9
    assert sweep_status(f).text().count("completed: 0/9") == 1
    ds = sweep(f)
    assert (tmp_path / "s.zarr" / "zarr.json").is_file()
    assert ds.attrs["study_text"] == f.read_text() and ds.attrs["brakesqueal_version"] == brakesqueal.__version__
    assert ds.attrs["study_hash"] == st.hash()
    s = sweep_status(f)
    assert s.complete and s.completed == list(range(9)) and not s.corrupt
    calls = []
    orig = runner.compute_chunk
    monkeypatch.setattr(runner, "compute_chunk", lambda *a: calls.append(1) or orig(*a))
    again = sweep(f)
    assert calls == []
    same_results(ds, again)
    # comments and layout of the file do not change the study; a different axis does
    g = write(tmp_path / "g.toml", "# comment\n" + STUDY3.format(q=json.dumps(EIGEN)).replace('"0.05:1:12"', '"0.05:1:12:lin"'))
    assert load_study(g).hash() == st.hash()
    assert load_study(write(tmp_path / "h.toml", STUDY3.format(q='["stable"]'))).hash() != st.hash()


def test_truncated_corrupt_and_missing_chunks_are_recomputed(tmp_path, monkeypatch):
    import zarr

    import brakesqueal.sweep.runner as runner

    f = write(tmp_path / "s.toml", STUDY3.format(q=json.dumps(EIGEN)))
    ref = sweep(f, store=tmp_path / "ref.zarr").load()
    store = tmp_path / "s.zarr"
    sweep(f)
    # 1: truncate a data chunk file; 2: change values silently (decodable, wrong); 3: delete a marker
    chunk_file = store / "max_real" / "c" / "0" / "1" / "0"
    data = chunk_file.read_bytes()
    chunk_file.write_bytes(data[: len(data) // 2])
    g = zarr.open_group(str(store), mode="r+")
    st = load_study(f)
    g["status"][st.region(5)] = np.int8(3)
    (store / MARKERS / "7.json").unlink()
    s = sweep_status(f)
    assert s.corrupt == [1, 5] and s.missing == [1, 5, 7]
    assert "corrupt (will be recomputed): 2 [1, 5]" in s.text()
    calls = []
    orig = runner.compute_chunk
    monkeypatch.setattr(runner, "compute_chunk", lambda spec, coords: calls.append(1) or orig(spec, coords))
    out = sweep(f)
    assert len(calls) == 3
    same_results(ref.drop_attrs(), out.drop_attrs())
    np.testing.assert_array_equal(out["max_real"].values, ref["max_real"].values)
    assert sweep_status(f).complete


def test_different_study_refused_and_overwrite(tmp_path, capsys):
    f = write(tmp_path / "s.toml", STUDY3.format(q='["stable"]'))
    g = write(tmp_path / "g.toml", STUDY3.format(q='["stable"]').replace("0.05:1:12", "0.1:1:12"))
    store = tmp_path / "s.zarr"
    assert main(["sweep", str(f), "--no-progress"]) == 0
    before = sorted(p.name for p in (store / MARKERS).iterdir())
    capsys.readouterr()
    assert main(["sweep", str(g), "--out", str(store)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(store) in err and "study_hash" in err and "--overwrite" in err
    assert main(["sweep", "--status", str(g), "--out", str(store)]) == 2
    assert sorted(p.name for p in (store / MARKERS).iterdir()) == before
    assert main(["sweep", str(g), "--out", str(store), "--overwrite", "--format", "json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["computed_chunks"] == 9 and out["reused_chunks"] == 0
    assert open_sweep(store).attrs["study_hash"] == load_study(g).hash()
    # never delete something that is not a Zarr store
    other = tmp_path / "notes"
    other.mkdir()
    (other / "keep.txt").write_text("x")
    assert main(["sweep", str(f), "--out", str(other), "--overwrite"]) == 2
    assert (other / "keep.txt").exists()


def test_cli_status_and_run(tmp_path, capsys):
    f = write(tmp_path / "s.toml", STUDY3.format(q='["stable"]'))
    assert main(["sweep", "--status", str(f), "--format", "json"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["exists"] is False and s["n_chunks"] == 9 and len(s["missing"]) == 9
    assert main(["sweep", str(f)]) == 0
    assert "9 computed, 0 reused" in capsys.readouterr().out
    assert main(["sweep", str(f)]) == 0
    assert "0 computed, 9 reused" in capsys.readouterr().out
    assert main(["sweep", "--status", str(f)]) == 0
    assert "completed: 9/9 chunks (100.0 %)" in capsys.readouterr().out


# ---------------------------------------------------------------- bad input
BAD = [
    ('preset = "paper-fig2"\ncolour = 1\n[axes]\nmu = "0.1:1:5"', "key 'colour': unknown key"),
    ('preset = "paper-fig2"\n[axes]\nmu = { start = 0.1, stop = 1, num = 5, step = 1 }', "key 'axes.mu.step'"),
    ('preset = "paper-fig2"\n[compute]\nquantity = ["stable"]\n[axes]\nmu = "0.1:1:5"', "key 'compute.quantity'"),
    ('preset = "paper-fig2"\n[axes]\nmu = []', "key 'axes.mu': empty axis"),
    ('preset = "paper-fig2"\n[axes]\nmu = { start = 0.1, stop = 1, num = 0 }', "key 'axes.mu.num': empty axis"),
    ('preset = "paper-fig2"\n[axes]\nmu = "0.1:1:0"', "key 'axes.mu': empty axis"),
    ('preset = "paper-fig2"\n[axes]\n', "key 'axes': empty"),
    ('preset = "paper-fig2"\n[axes]\nN0 = "1000:4000:5"', "key 'axes.N0': cannot vary 'N0': it is tied"),
    ('preset = "paper-fig2"\n[samples]\nn = 10\n[samples.ranges]\nmu1 = "0.1:1"', "key 'samples.ranges.mu1'"),
    ('preset = "paper-fig2"\n[samples]\nn = 0\n[samples.ranges]\nmu = "0.1:1"', "key 'samples.n'"),
    ('preset = "paper-fig2"\n[samples]\nn = -5\n[samples.ranges]\nmu = "0.1:1"', "key 'samples.n'"),
    ('preset = "paper-fig2"\n[axes]\nfoo = "1:2:3"', "key 'axes.foo': unknown parameter 'foo'"),
    ('preset = "paper-fig2"\n[compute]\nquantities = ["squeal"]\n[axes]\nmu = "0.1:1:5"', "unknown quantity"),
    ('[axes]\nmu = "0.1:1:5"', "key 'preset': missing"),
    ('preset = "paper-fig2"\n[tied]\nfoo = "2"\n[axes]\nk_ip = "1:2:3"', "key 'tied.foo': cannot tie 'foo'"),
    ('preset = "paper-fig3"\n[tied]\nmu2 = "1 - mu1"\n[axes]\nmu2 = "0.1:0.9:3"', "key 'axes.mu2': cannot vary"),
    ('preset = "paper-fig2"\n[axes]\nmu = "0.1:1:5"\n[samples]\nn = 3', "exactly one of [axes]"),
    ('preset = "paper-fig2"\n[axes]\nmu = "0.1:1:5', "is not valid TOML"),
    ('preset = "paper-fig3"\n[tied]\nk_ip1 = "k_ip2"\nk_ip2 = "2 * k_ip1"\n[axes]\nmu = "0.1:1:3"',
     "key 'tied.k_ip1': preset 'paper-fig3+ties': the definitions form a cycle"),
    ('preset = "paper-fig3"\n[tied]\nh10 = "h20"\nh20 = "k_ip2"\nk_ip2 = "h10 * 1e9"\n[axes]\nmu = "0.1:1:3"',
     "key 'tied.h10'"),
]


@pytest.mark.parametrize(("text", "needle"), BAD)
def test_bad_study_one_line_exit_2(tmp_path, capsys, text, needle):
    f = write(tmp_path / "bad.toml", text)
    assert main(["sweep", str(f)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and needle in err and "bad.toml" in err
    assert not (tmp_path / "bad.zarr").exists()


@pytest.mark.slow
def test_unreachable_scheduler_fails_fast(tmp_path, capsys):
    f = write(tmp_path / "s.toml", STUDY3.format(q='["stable"]'))
    t0 = time.perf_counter()
    assert main(["sweep", str(f), "--scheduler", "tcp://127.0.0.1:9"]) == 2
    assert time.perf_counter() - t0 < 10
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "tcp://127.0.0.1:9" in err
    assert not (tmp_path / "s.zarr").exists()
    with pytest.raises(ParameterError, match="at most one of"):
        sweep(f, workers=2, scheduler="tcp://127.0.0.1:9")
    with pytest.raises(ParameterError, match="--workers"):
        sweep(f, workers=0)
