"""Outputs of the exact-pads branch (``HarmonicBranch.data``, ``.plot``, ``cycles --exact-pads --out/--plot``).

The Dataset and the NetCDF file written by the CLI must hold exactly the numbers of the branch's points (read
back with xarray), and the figure must draw them (its line data are compared with the points).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr

from brakesqueal import Axis
from brakesqueal.cli import main
from brakesqueal.model.options import resolve_space
from brakesqueal import harmonic_branch

SETS = ["mu1=0.5", "mu2=0.5", "k_ip1=1e6", "k_ip2=1e6"]


@pytest.fixture(scope="module")
def branch():
    return harmonic_branch(resolve_space(preset="paper-fig3", sets=SETS), Axis("Omega", 60.0, 70.0), max_points=5)


def test_dataset_holds_the_points(branch):
    ds = branch.data
    pts = branch.points
    assert ds.sizes["point"] == len(pts) >= 3
    np.testing.assert_array_equal(ds["p"].values, [pt.p for pt in pts])
    np.testing.assert_array_equal(ds["frequency"].values, [pt.frequency_hz for pt in pts])
    np.testing.assert_array_equal(ds["amplitude"].sel(coord="q1").values, [pt.amplitude["q1"] for pt in pts])
    np.testing.assert_array_equal(ds["F_n_min"].values, [pt.F_n_min for pt in pts])
    assert ds["stable"].values.tolist() == [-1 if pt.stable is None else int(pt.stable) for pt in pts]
    assert ds.attrs["status"] == branch.status and ds.attrs["hopf_p0"] == branch.hopf.hopf.p0
    assert list(ds["coord"].values) == list(branch.coords) and list(ds["pad"].values) == list(branch.pads)


def test_figure_draws_the_points(branch):
    fig = branch.plot()
    amp_ax, fr_ax = fig.axes[:2]
    xs = np.concatenate([ln.get_xdata() for ln in amp_ax.lines if len(ln.get_xdata()) == 2])
    ys = np.concatenate([ln.get_ydata() for ln in amp_ax.lines if len(ln.get_xdata()) == 2])
    for pt in branch.points:  # every point is a segment end
        assert np.any(np.isclose(xs, pt.p, rtol=0, atol=0) & np.isclose(ys, pt.amplitude["q1"], rtol=1e-15))
    assert "Hopf point" in [t.get_text() for t in amp_ax.get_legend().get_texts()]
    assert fr_ax.get_ylabel() == "frequency [Hz]"
    with pytest.raises(Exception, match="'coord' must be one of"):
        branch.plot("nope")


def test_cli_writes_netcdf_and_plot(tmp_path, capsys, branch):
    out, png = tmp_path / "b.nc", tmp_path / "b.png"
    assert main(["cycles", "--preset", "paper-fig3", *[a for s in SETS for a in ("--set", s)], "--along",
                 "Omega=60:70", "--exact-pads", "--max-points", "5", "--out", str(out), "--plot", str(png),
                 "--format", "json"]) == 0
    d = json.loads(capsys.readouterr().out)
    with xr.open_dataset(out) as ds:
        np.testing.assert_allclose(ds["p"].values, [pt["p"] for pt in d["points"]], rtol=0)
        np.testing.assert_allclose(ds["p"].values, branch.data["p"].values, rtol=1e-12)
        assert ds.attrs["parameter"] == "Omega"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(["cycles", "--along", "Omega=60:70", "--exact-pads", "--out", str(tmp_path / "x.txt")]) == 2
    assert "--out" in capsys.readouterr().err


def test_pad_modes_enter_the_stability_verdict(branch):
    """The pads' fast modes: -G_L/G_Ldot averaged over the phases where the rate enters (a synthetic Jacobian
    with known entries), negative for the Coulomb pads of the branch (whose verdicts are therefore the band's)."""
    from brakesqueal.nonlinear.harmonic import pad_mode_rates

    n, m, M = 2, 2, 4
    J = np.zeros((n + m, 3 * n + 2 * m, M))
    J[n, 3 * n, :] = 1.0
    J[n, 3 * n + m, :] = [1e-6, 2e-6, 0.0, 4e-6]  # pad 1: rates -1e6, -5e5, (none), -2.5e5
    J[n + 1, 3 * n + 1, :] = 1.0
    J[n + 1, 3 * n + m + 1, :] = -1e-3  # pad 2: a falling law's unstable mode, +1e3 1/s
    np.testing.assert_allclose(pad_mode_rates(J, n, m), [np.mean([-1e6, -5e5, -2.5e5]), 1e3])
    assert any(pt.stable is not None for pt in branch.points)
    assert all(pt.stable in (True, None) for pt in branch.points[:3])  # supercritical onset: stable cycles


@pytest.mark.parametrize("name", ["paper", "minimal", "in-plane-pad", "four-pad"])
def test_no_unstable_verdict_next_to_a_supercritical_onset(name):
    """Every built-in model whose first path crosses supercritically: the first orbits past the onset are stable
    (Hopf theorem).  Hill's radial exponent there, -2 mu' (p - p0), is below the method's accuracy
    (``hill_accuracy``); such orbits take the normal form's verdict instead of a sign of rounding (they were
    reported unstable, or without a verdict, at some of these points)."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from test_pad_limit_and_api_matrix import PATHS

    from brakesqueal.model import ParameterSpace

    pname, a, b, log = PATHS[name][0]
    br = harmonic_branch(ParameterSpace.from_preset(name), Axis(pname, a, b, 2, log), max_points=6)
    assert br.hopf.hopf.criticality == "supercritical"
    verdicts = [pt.stable for pt in br.points]
    assert verdicts[0] is True and all(v is True for v in verdicts), verdicts
    for pt in br.points:  # no contradiction: a positive exponent beside "stable" is one without a reliable sign
        d = pt.to_dict()
        worst = max(e[0] for e in d["floquet_exponents"])
        assert worst < 0 or (d["stability_from"] == "normal form" and worst <= d["hill_accuracy"]), d


@pytest.mark.slow
@pytest.mark.parametrize("name", ["six-dof", "eight-dof"])
def test_subcritical_onsets_of_the_larger_models_agree_with_shooting(name):
    """The 6- and 8-DOF models (pads with mass: no pad unknowns, so harmonic balance and shooting solve the same
    equations): the harmonic-balance Newton converges (it stalled at a scaled step of 1e-7 against a 1e-10
    tolerance, at the noise floor of these larger systems) and its verdicts equal the shooting branch's
    Floquet verdicts (subcritical onsets: unstable cycles)."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from test_pad_limit_and_api_matrix import PATHS

    from brakesqueal.model import ParameterSpace
    from brakesqueal import squeal_branch

    pname, a, b, log = PATHS[name][0]
    space = ParameterSpace.from_preset(name)
    hb = harmonic_branch(space, Axis(pname, a, b, 2, log), max_points=4)
    sb = squeal_branch(space, Axis(pname, a, b, 2, log), max_points=4)
    assert hb.hopf.hopf.criticality == sb.hopf.branch_start.criticality == "subcritical"
    assert hb.hopf.hopf.p0 == pytest.approx(sb.hopf.branch_start.p0, rel=1e-7)
    assert [pt.stable for pt in hb.points] == [False] * len(hb.points)
    assert not sb.data["stable"].values.any()
    assert max(pt.residual for pt in hb.points) < 1e-9
