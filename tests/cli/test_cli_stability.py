"""Command line: crossings, critical-speed, map, reproduce and the bad-input contract."""

from __future__ import annotations

import json

import numpy as np
import pytest

from brakesqueal.cli import main
from brakesqueal import linearize
from brakesqueal.model import get_preset
from brakesqueal.results import open_map


def run(capsys, *args):
    rc = main(list(args))
    out = capsys.readouterr()
    return rc, out.out, out.err


def test_crossings_json(capsys):
    rc, out, _ = run(capsys, "crossings", "--along", "k_ip=1e5:1e10:log", "--set", "mu=0.7", "--format", "json")
    assert rc == 0
    data = json.loads(out)
    assert data["parameter"] == "k_ip" and isinstance(data["stable_at_start"], bool)
    assert [c["direction"] for c in data["crossings"]] == ["stabilizing", "destabilizing"]
    pre = get_preset("paper-fig2")
    for c in data["crossings"]:
        lo = linearize(pre.resolve({"mu": 0.7, "k_ip": c["value"] * 0.999})).max_real
        hi = linearize(pre.resolve({"mu": 0.7, "k_ip": c["value"] * 1.001})).max_real
        assert (lo > 0 and hi < 0) if c["direction"] == "stabilizing" else (lo < 0 and hi > 0)


def test_critical_speed_json(capsys):
    rc, out, _ = run(capsys, "critical-speed", "--preset", "paper-fig3", "--range", "1:1e5", "--format", "json")
    assert rc == 0
    data = json.loads(out)
    assert data["Omega_crit"] == data["crossings"][0]["value"]
    pre = get_preset("paper-fig3")
    w = data["Omega_crit"]
    assert linearize(pre.resolve({"Omega": w * 0.999})).max_real < 0 < linearize(pre.resolve({"Omega": w * 1.001})).max_real
    rc, out, _ = run(capsys, "critical-speed", "--preset", "paper-fig3", "--set", "mu1=0.95", "--set", "mu2=0.05",
                     "--format", "json")
    assert rc == 0 and json.loads(out)["Omega_crit"] is None


def test_map_writes_netcdf_and_plot(tmp_path, capsys):
    nc, png = tmp_path / "m.nc", tmp_path / "m.png"
    rc, _, err = run(capsys, "map", "--x", "k_ip=1e5:1e10:20:log", "--y", "mu=0.1:1:15", "--out", str(nc),
                     "--plot", str(png))
    assert rc == 0, err
    m = open_map(str(nc))
    assert m.data["stable"].dtype == bool and m.data.sizes["k_ip"] == 20 and m.data.sizes["mu"] == 15
    assert png.stat().st_size > 1000
    pre = get_preset("paper-fig2")
    k, mu = float(m.data["k_ip"][5]), float(m.data["mu"][10])
    assert bool(m.data["stable"].sel(k_ip=k, mu=mu)) == (linearize(pre.resolve({"k_ip": k, "mu": mu})).max_real < 0)


@pytest.mark.parametrize("args, fragment", [
    (["map", "--x", "k_ip=1e10:1e5:10:log", "--y", "mu=0.1:1:10"], "reversed"),
    (["map", "--x", "k_ip=0:1e5:10:log", "--y", "mu=0.1:1:10"], "positive"),
    (["map", "--x", "k_ip=1:1e5:1", "--y", "mu=0.1:1:10"], "at least 2"),
    (["map", "--x", "k_ip=1:1e5:100000", "--y", "mu=0.1:1:100000"], "--force"),
    (["map", "--x", "foo=1:2:3", "--y", "mu=0.1:1:10"], "foo"),
    (["crossings", "--along", "k_ip=5:1"], "reversed"),
    (["critical-speed", "--range", "0:10"], "positive"),
    (["map", "--x", "k_ip=1e5:1e10:100000:log", "--y", "mu=0.1:1:100000", "--force"], "at most 4 GiB"),
    (["map", "--x", "k_ip=1e5:1e10:10:log", "--y", "mu=0.1:1:10", "--plot", "m.xyz"], "--plot"),
    (["crossings", "--along", "k_ip=1e5:1e10:log", "--plot", "no/such/dir/c.png"], "does not exist"),
    (["map", "--model", "belt", "--preset", "paper-fig2", "--x", "slope=0:1:3", "--y", "m=1:2:3"], "paper-fig2"),
])
def test_bad_input_one_line_exit_2(tmp_path, capsys, monkeypatch, args, fragment):
    monkeypatch.chdir(tmp_path)
    rc, _, err = run(capsys, *args, *(["--out", str(tmp_path / "x.nc")] if args[0] == "map" else []))
    assert rc == 2
    assert err.count("\n") == 1 and fragment in err
    assert not (tmp_path / "x.nc").exists()


def test_output_paths_are_checked_before_computing(tmp_path, capsys, monkeypatch):
    """A bad --out fails at once, before the (here deliberately slow) map is computed; an old file survives errors."""
    import brakesqueal.analysis.quantities as quantities

    called = []
    monkeypatch.setattr(quantities, "evaluate_block", lambda *a, **k: called.append(1))
    rc, _, err = run(capsys, "map", "--x", "k_ip=1e5:1e10:5:log", "--y", "mu=0.1:1:5", "--out", str(tmp_path / "m.txt"))
    assert rc == 2 and ".nc" in err and not called
    old = tmp_path / "old.nc"
    old.write_bytes(b"previous results")
    rc, _, err = run(capsys, "map", "--x", "foo=1:2:3", "--y", "mu=0.1:1:3", "--out", str(old))
    assert rc == 2 and old.read_bytes() == b"previous results"
    assert [p.name for p in tmp_path.iterdir()] == ["old.nc"]  # no temporary file left behind


def test_map_no_eigen_leaves_the_eigenvalue_variables_out(tmp_path, capsys):
    nc = tmp_path / "v.nc"
    rc, out, err = run(capsys, "map", "--x", "k_ip=1e5:1e10:12:log", "--y", "mu=0.1:1:9", "--out", str(nc), "--no-eigen")
    assert rc == 0, err
    m = open_map(str(nc))
    assert {v for v in m.data.data_vars if not v.startswith("boundary_")} == {"stable", "status", "carrier", "route", "disk_stable"}
    assert {"boundary_k_ip", "boundary_mu"} <= set(m.data.data_vars)  # the refined boundary needs no eigenvalues
    full = run(capsys, "map", "--x", "k_ip=1e5:1e10:12:log", "--y", "mu=0.1:1:9", "--out", str(tmp_path / "f.nc"))
    assert full[0] == 0
    f = open_map(str(tmp_path / "f.nc"))
    np.testing.assert_array_equal(f.data["stable"].values, m.data["stable"].values)
    assert np.array_equal(f.data["stable"].values, f.data["max_real"].values < 0)


@pytest.mark.parametrize("model,args", [
    ("six-dof", ["--x", "k_c=1e8:1e10:6:log", "--y", "mu1=0.45:0.55:3"]),
    ("belt", ["--x", "slope=0:0.02:5", "--y", "d_ip=0.1:1:3"]),
])
def test_map_of_any_model_uses_the_shared_options(tmp_path, capsys, model, args):
    """--model/--set are resolved like everywhere else: the map equals stability_map on resolve_space."""
    from brakesqueal import stability_map
    from brakesqueal.analysis.maps import parse_axis
    from brakesqueal.model import resolve_space

    nc = tmp_path / "m.nc"
    rc, out, err = run(capsys, "map", "--model", model, "--set", "N0=3000", *args, "--out", str(nc))
    assert rc == 0, err
    got = open_map(str(nc)).data
    ref = stability_map(resolve_space(model, sets=["N0=3000"]), parse_axis(args[1]), parse_axis(args[3])).data
    assert got.attrs["model"] == model and got.attrs["method"] == ref.attrs["method"]
    np.testing.assert_array_equal(got["stable"].values, ref["stable"].values)
    np.testing.assert_array_equal(got["status"].values, ref["status"].values)


def test_crossings_plot_draws_the_stored_profile(tmp_path, capsys):
    png = tmp_path / "c.png"
    rc, out, err = run(capsys, "crossings", "--along", "k_ip=1e5:1e10:log", "--set", "mu=0.7", "--plot", str(png))
    assert rc == 0, err
    assert png.stat().st_size > 1000 and "k_ip =" in out


@pytest.mark.slow
def test_reproduce_fig3_small(tmp_path, monkeypatch):
    from brakesqueal import reproduce

    s = reproduce.reproduce_fig3(tmp_path, n_diff=21)
    assert (tmp_path / "fig3.png").exists() and (tmp_path / "fig3.nc").exists() and (tmp_path / "fig3.csv").exists()
    for c in s["curves"].values():
        assert np.isfinite(c["Omega_crit_at_equal_mu"])


def test_an_axis_over_a_tied_name_replaces_its_tie(tmp_path, capsys):
    """mu1 and mu2 are tied to mu in paper-fig2: the map's axes replace the ties (noted), as --set would."""
    rc, out, err = run(capsys, "map", "--preset", "paper-fig2", "--x", "mu1=0:1:6", "--y", "mu2=0:1:6",
                       "--out", str(tmp_path / "m.nc"))
    assert rc == 0, err
    assert "the --x axis replaces the tie mu1 = mu" in err and "the --y axis replaces the tie mu2 = mu" in err
    m = open_map(tmp_path / "m.nc")
    assert m.dims == ("mu2", "mu1")
    # the asymmetric corners are off the tie: a map of mu alone could not show them
    pre = get_preset("paper-fig2")
    lm = linearize(pre.resolve({"mu1": 1.0, "mu2": 0.0}))
    assert bool(m.data.stable.sel(mu1=1.0, mu2=0.0)) == (lm.max_real < 0)
    rc, out, err = run(capsys, "crossings", "--preset", "paper-fig2", "--along", "mu1=0.05:1")
    assert rc == 0 and "the --along axis replaces the tie mu1 = mu" in err


@pytest.mark.slow
def test_forty_random_tilted_sets_never_call_a_0_hz_pad_mode_squeal(capsys):
    """Asymmetric friction tilts the silent motion; a massless pad's own non-oscillatory mode may then be
    unstable.  ``linearize`` says "squeal" only for a verdict carried by a vibrating (f > 0) mode, and names the
    pad's mode and the disk modes' own verdict otherwise (checked against eigen_analysis with modes="disk")."""
    import re

    from brakesqueal import eigen_analysis

    rng = np.random.default_rng(29)
    pre = get_preset("paper-fig2")
    pad_carried = 0
    for _ in range(40):
        mu1, mu2 = (float(v) for v in rng.uniform(0.05, 1.0, 2))
        rc, out, err = run(capsys, "linearize", "--preset", "paper-fig2", "--set", f"mu1={mu1!r}",
                           "--set", f"mu2={mu2!r}")
        assert rc == 0, err
        head = next(line for line in out.splitlines() if line.startswith("Silent motion is"))
        v = eigen_analysis(linearize(pre.resolve({"mu1": mu1, "mu2": mu2}))).verdict()
        if "squeal" in head:
            assert v.status == "unstable" and not v.pad_mode and v.frequency > 0, head
            assert re.search(r"carried by a .* mode at [0-9.e+]+ Hz", head), head
        if v.pad_mode:
            pad_carried += 1
            assert "squeal" not in head and "a non-oscillatory mode of the massless pad alone" in out
            assert "disk modes alone:" in out
    assert pad_carried > 0  # the sample does reach pad-carried verdicts
