"""The command line's input rules across commands: one-line errors naming the option (exit 2), summaries that
count points without a verdict, axes finer than the floating-point resolution, ``--set`` of a swept name,
choices in ``--help``, and the agreement of text and JSON."""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest

from brakesqueal import Axis
from brakesqueal.analysis.maps import MapSummary, resolution_problem
from brakesqueal.cli import main
from brakesqueal.errors import ParameterError
from brakesqueal.results import CriticalSpeedResult


def cli(capsys, *args: str) -> tuple[int, str, str]:
    rc = main(list(args))
    out = capsys.readouterr()
    return rc, out.out, out.err


def one_line_error(rc: int, err: str) -> str:
    assert rc == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("brakesqueal: error: ") and "Traceback" not in err, err
    return lines[0]


# ---------------------------------------------------------------- 1. map summary: points without a verdict

def test_map_summary_counts_invalid_points_apart(capsys, tmp_path):
    """mu = 0 is outside mu's allowed range: 5 invalid points are counted apart, not as 'not stable'."""
    import xarray as xr

    out = tmp_path / "m.nc"
    rc, text, err = cli(capsys, "map", "--x", "mu=0:1:5", "--y", "k_ip=1e5:1e9:5:log", "--out", str(out))
    assert rc == 0, err
    with xr.open_dataset(out) as ds:  # the counts, independently from the file
        status, stable = ds["status"].values, ds["stable"].values.astype(bool)
    decided = np.isin(status, (0, 1))
    n_st, n_un, n_none = int(stable.sum()), int((decided & ~stable).sum()), int((~decided).sum())
    assert n_none == 5 and (status[~decided] == 4).all()
    pct = f"({100 * n_st / (n_st + n_un):.1f}% / {100 * n_un / (n_st + n_un):.1f}% of the {n_st + n_un} with a verdict)"
    assert f"25 points: {n_st} stable, {n_un} unstable {pct}; 5 without a verdict (invalid_parameters 5)" in text
    assert "20.0% stable" not in text


def test_map_without_any_verdict_has_no_percentage_and_plots_without_warnings(capsys, tmp_path):
    """mu < 0 everywhere: no point has a verdict (status 4); the summary must not read '0.0% stable', and the
    plot must not warn ('Mean of empty slice')."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rc, text, err = cli(capsys, "map", "--x", "mu=-1:-0.5:3", "--y", "k_ip=1e5:1e9:3:log", "--out",
                            str(tmp_path / "u.nc"), "--plot", str(tmp_path / "u.png"))
    assert rc == 0, err
    assert "9 points: 0 stable, 0 unstable; 9 without a verdict (invalid_parameters 9)" in text
    assert "% stable" not in text and err == ""


def test_map_summary_text_of_every_mix():
    ax = Axis("mu", 0.1, 1.0, 2)
    s = MapSummary(10, 0.3, "m", ax, ax, {"ok": 7, "contact_loss": 2, "undecided": 1}, 4)
    assert s.stable == 3 and s.decided == 7
    assert s.text() == ("10 points: 3 stable, 4 unstable (42.9% / 57.1% of the 7 with a verdict); 3 without a "
                        "verdict (contact_loss 2, undecided 1)")
    assert MapSummary(4, 1.0, "m", ax, ax, {"ok": 4}, 0).text() == (
        "4 points: 4 stable, 0 unstable (100.0% / 0.0% of the 4 with a verdict)")


# ---------------------------------------------------------------- 2. axes finer than the float resolution

def test_resolution_rule_is_one_rule():
    assert resolution_problem(0.1, 0.10000000000000003, 100, False) is not None
    assert resolution_problem(0.1, 0.2, 100, False) is None
    assert resolution_problem(1.0, 1.0 + 1e-13, 100, True) is not None
    assert resolution_problem(1.0, 10.0, 100, True) is None
    with pytest.raises(ParameterError, match="floating-point resolution"):
        Axis("mu", 0.1, 0.10000000000000003, 100)
    # the accepted ranges have distinct, increasing values
    for lo, hi, n, log in ((0.1, 0.1 + 1e-12, 100, False), (1.0, 1.0 + 1e-9, 1000, True)):
        assert resolution_problem(lo, hi, n, log) is None
        assert np.all(np.diff(Axis("mu", lo, hi, n, log).values()) > 0)


@pytest.mark.parametrize("args", [
    ("map", "--x", "mu=0.1:0.10000000000000003:100", "--y", "k_ip=1e5:1e9:5:log", "--out", "OUT.nc"),
    ("modes", "--along", "mu=0.1:0.1000000000000001", "--num", "100"),
    ("crossings", "--along", "mu=0.1:0.10000000000000003"),
    ("hopf", "--along", "mu=0.1:0.10000000000000003"),
    ("cycles", "--along", "mu=0.1:0.10000000000000003"),
    ("critical-speed", "--range", "1:1.0000000000000002"),
])
def test_every_axis_refuses_ranges_finer_than_float_resolution(capsys, tmp_path, args):
    args = tuple(a.replace("OUT", str(tmp_path / "x")) for a in args)
    line = one_line_error(*cli(capsys, *args)[::2])
    assert "closer than the floating-point resolution" in line


# ---------------------------------------------------------------- 5. critical speed: text and JSON agree

@pytest.mark.parametrize("stable0, crossings, undecided, exhaustive, outcome, head", [
    (True, ((50.0, "destabilizing"),), (), True, "onset", "Omega_crit = 50 rad/s"),
    (False, (), (), True, "unstable_throughout", "unstable throughout the range"),
    (False, (), (), False, "unstable_throughout", "unstable throughout the range (at every grid point"),
    (True, (), (), True, "stable_throughout", "stable throughout the range"),
    (True, (), (), False, "unknown", "UNKNOWN (stable at every grid point"),
    (False, ((30.0, "stabilizing"),), (), True, "unstable_at_start", "unstable already at the start"),
    (True, (), ((10.0, 20.0),), True, "unknown", "UNKNOWN"),
    (False, (), ((10.0, 20.0),), False, "unknown", "UNKNOWN"),
    (True, ((50.0, "destabilizing"),), ((10.0, 20.0),), True, "onset", "NOT certain"),
    # squeal from the range start, re-stabilised, then a second onset: the head leads with the start, not 35
    (False, ((11.56, "stabilizing"), (35.0, "destabilizing")), (), True, "unstable_at_start",
     "Squeal from the range start: unstable already at the start of the range, from 1 (the range start) up to "
     "11.56 rad/s, and from 35 up to the range end"),
])
def test_critical_speed_text_and_json_agree(stable0, crossings, undecided, exhaustive, outcome, head):
    r = CriticalSpeedResult("Omega", 1.0, 1e3, True, stable0, crossings, "test", undecided_ranges=undecided,
                            exhaustive=exhaustive)
    d = r.to_dict()
    first = r.text().splitlines()[0]
    assert d["outcome"] == outcome and head in first
    assert ("UNKNOWN" in first) == (d["Omega_crit"] is None and bool(d["undecided_ranges"] or (
        d["stable_at_start"] and not d["exhaustive"])))
    if d["Omega_crit"] is None:
        assert ("undecided" in first) == bool(d["undecided_ranges"])
    assert ("throughout" in first) == (outcome in ("stable_throughout", "unstable_throughout"))
    assert ("unstable" in (first.split(":") + [""])[1]) == (outcome in ("unstable_throughout", "unstable_at_start"))
    # the unstable intervals, read off the start verdict and the crossings, lead the JSON too
    iv = d["unstable_intervals"]
    assert d["squeal_from"] == (iv[0][0] if iv else None)
    assert (d["squeal_from"] == 1.0) == (not stable0) == (first.startswith("Squeal from the range start")
                                                          or "unstable throughout" in first)
    assert all(a < b for a, b in iv) and all(iv[i][1] <= iv[i + 1][0] for i in range(len(iv) - 1))


def test_critical_speed_leads_with_low_speed_squeal():
    """A model unstable from the range start up to 11.56 rad/s and again from 35 (the Stribeck case of issue
    29): text and JSON lead with the start, list both intervals and do not call it an onset at 35."""
    r = CriticalSpeedResult("Omega", 1.0, 1e5, True, False, ((11.56, "stabilizing"), (35.0, "destabilizing")),
                            "test", exhaustive=True)
    d = r.to_dict()
    assert d["outcome"] == "unstable_at_start" and d["squeal_from"] == 1.0
    assert d["unstable_intervals"] == [[1.0, 11.56], [35.0, 1e5]]
    first = r.text().splitlines()[0]
    assert first.startswith("Squeal from the range start") and first.index("11.56") < first.index("35")


def test_critical_speed_of_the_belt_says_unstable_throughout(capsys):
    rc, text, err = cli(capsys, "critical-speed", "--model", "belt")
    assert rc == 0, err
    rc, js, err = cli(capsys, "critical-speed", "--model", "belt", "--format", "json")
    d = json.loads(js)
    assert d["undecided_ranges"] == [] and d["stable_at_start"] is False and d["outcome"] == "unstable_throughout"
    assert "unstable throughout the range" in text and "UNKNOWN" not in text


# ---------------------------------------------------------------- 6, 7, 10, 11: one-line errors naming options

@pytest.mark.parametrize("args, expected", [
    (("eigen", "--mode", "99"), "--mode must be in [0, 3]"),
    (("eigen", "--model", "eight-dof", "--mode", "16"), "--mode must be in [0, 15]"),
    (("simulate", "--t-end", "1e308"), "'--sample-rate' and '--t-end' ask for inf output samples"),
    (("critical-speed", "--range", "1:2:log"), "--range must be START:STOP in rad/s with 0 < START < STOP"),
    (("critical-speed", "--range", "0:1e5"), "--range must be START:STOP in rad/s with 0 < START < STOP"),
    (("simulate", "--pad-damping", "-1"), "The option '--pad-damping' must be in (0, 1e+06]"),
    (("simulate", "--pad-slope", "1"), "The option '--pad-slope' must be in (0, 0.01]"),
    (("simulate", "--pad-slope", "1e-4", "--stick-speed", "5"), "The option '--stick-speed' must be in (0, 1]"),
    (("simulate", "--rtol", "1"), "The option '--rtol' must be in [1e-13, 1e-2]"),
    (("simulate", "--sample-rate", "-1"), "The option '--sample-rate' must be a positive number"),
    (("simulate", "--method", "foo"), "The option '--method' must be one of DOP853-jit"),
    (("simulate", "--events", "foo"), "'--events'"),
    (("simulate", "--plot", "s.eps"), "--plot: 's.eps' must end in .png or .svg or .pdf"),
])
def test_errors_name_the_option_and_its_range(capsys, args, expected):
    line = one_line_error(*cli(capsys, *args)[::2])
    assert expected in line
    assert "log:log" not in line and "a log axis" not in line


def test_simulate_api_bounds_the_number_of_samples():
    from brakesqueal import simulate
    from brakesqueal.model import get_preset

    p = get_preset("paper-fig2").resolve({})
    with pytest.raises(ParameterError, match="at most 5e\\+07") as exc:
        simulate(p, 1e308)
    assert exc.value.parameter == "sample_rate" and "t_end" in exc.value.names


# ---------------------------------------------------------------- 12. --set of the varied name

@pytest.mark.parametrize("args, option", [
    (("crossings", "--along", "mu=0.1:1", "--set", "mu=0.3"), "--along"),
    (("hopf", "--along", "mu=0.1:1", "--set", "mu=0.3"), "--along"),
    (("cycles", "--along", "mu=0.1:1", "--set", "mu=0.3"), "--along"),
    (("modes", "--along", "mu=0.1:1", "--set", "mu=0.3"), "--along"),
    (("map", "--x", "k_ip=1e5:1e9:5:log", "--y", "mu=0.1:1:3", "--out", "OUT.nc", "--set", "k_ip=inf"), "--x"),
    (("map", "--x", "k_ip=1e5:1e9:5:log", "--y", "mu=0.1:1:3", "--out", "OUT.nc", "--set", "mu=0.2"), "--y"),
    (("critical-speed", "--set", "Omega=10"), "--range"),
])
def test_set_of_the_varied_name_is_refused(capsys, tmp_path, args, option):
    args = tuple(a.replace("OUT", str(tmp_path / "x")) for a in args)
    line = one_line_error(*cli(capsys, *args)[::2])
    name = args[-1].split("=")[0]
    assert f"--set {name} is also the {option} axis" in line


# ---------------------------------------------------------------- 13. help

def test_help_shows_choices_and_a_bare_group_prints_its_help(capsys):
    rc, text, _ = cli(capsys, "simulate", "--help")
    assert rc == 0
    for opt in ("--format", "--events", "--contact"):
        assert f"{opt} <str>" not in text
    for choices in ("<text|json>", "<stop|continue|off>", "<bilateral|unilateral>"):
        assert choices in text
    rc, text, _ = cli(capsys, "cycles", "--help")
    assert rc == 0 and "<auto|exact|quasi-static>" in text and "<bilateral|unilateral>" in text
    rc, out, err = cli(capsys, "cache")
    assert rc == 0 and err == "" and out.startswith("Usage: brakesqueal cache") and "\n  info" in out


# ---------------------------------------------------------------- 14. the exact-pads table shows Fn min and max

def test_harmonic_table_shows_min_and_max_normal_force(capsys):
    rc, text, err = cli(capsys, "cycles", "--along", "mu=0.3:0.6", "--max-points", "3", "--no-progress")
    assert rc == 0, err
    head = next(line for line in text.splitlines() if "Fn min 1" in line)
    assert "Fn max 1" in head and "Fn max 2" in head
    row = text.splitlines()[text.splitlines().index(head) + 1].split()
    cols = head.replace("f [Hz]", "f").replace("tilt [rad]", "tilt").replace("Fn min ", "Fnmin").replace(
        "Fn max ", "Fnmax").replace("slide min", "slide").split()
    fmin, fmax = float(row[cols.index("Fnmin1")]), float(row[cols.index("Fnmax1")])
    assert 0 < fmin < fmax and not math.isnan(fmax)
