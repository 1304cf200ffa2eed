"""Command line: crossings, critical-speed, map, reproduce and the bad-input contract."""

from __future__ import annotations

import json

import numpy as np
import pytest

from brakesqueal.cli import main
from brakesqueal.analysis.linear import linearize
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
    (["map", "--x", "N0=1:2:3", "--y", "mu=0.1:1:10"], "tied"),
    (["crossings", "--along", "k_ip=5:1"], "reversed"),
    (["critical-speed", "--range", "0:10"], "positive"),
])
def test_bad_input_one_line_exit_2(tmp_path, capsys, args, fragment):
    rc, _, err = run(capsys, *args, *(["--out", str(tmp_path / "x.nc")] if args[0] == "map" else []))
    assert rc == 2
    assert err.count("\n") == 1 and fragment in err


def test_reproduce_fig3_small(tmp_path, monkeypatch):
    from brakesqueal import reproduce

    s = reproduce.reproduce_fig3(tmp_path, n_diff=21)
    assert (tmp_path / "fig3.png").exists() and (tmp_path / "fig3.nc").exists() and (tmp_path / "fig3.csv").exists()
    for c in s["curves"].values():
        assert np.isfinite(c["Omega_crit_at_equal_mu"])
