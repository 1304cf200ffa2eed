"""Mode tracking along a path (mode-coupling diagrams) against closed forms and the exact crossings."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from brakesqueal import modes_along
from brakesqueal.analysis.modes import track_modes
from brakesqueal.cli import main
from brakesqueal.model import resolve_space


@pytest.mark.parametrize("k1,k2", [(1.0, 2.0), (3.0, 1.5), (10.0, 10.5)])
def test_circulatory_coalescence_at_the_closed_form(k1, k2):
    # M q'' + K q = 0 with K = [[k1, mu], [-mu, k2]]: lambda^2 = -(k1+k2)/2 +- sqrt(((k1-k2)/2)^2 - mu^2),
    # the two frequencies merge (flutter) at mu = |k1 - k2| / 2 and one mode becomes unstable there
    mu_c = abs(k1 - k2) / 2
    values = np.linspace(0.0, 2 * mu_c, 81)
    tr = track_modes(values, lambda mu: (np.eye(2), np.zeros((2, 2)), np.array([[k1, mu], [-mu, k2]])))
    merges = [c for c in tr.coalescences if c["kind"] == "merge"]
    assert len(merges) == 1 and merges[0]["value"] == pytest.approx(mu_c, rel=1e-6)
    assert merges[0]["frequency_hz"] == pytest.approx(math.sqrt((k1 + k2) / 2) / (2 * math.pi), rel=1e-2)
    assert [c["direction"] for c in tr.crossings] == ["destabilizing"]
    assert tr.crossings[0]["value"] == pytest.approx(mu_c, rel=1e-6)


def test_tracks_are_continuous_through_a_crossing_of_frequencies():
    # two uncoupled modes whose frequencies cross: tracking must follow each mode (by its shape), not sort by frequency
    values = np.linspace(0.5, 2.0, 61)
    tr = track_modes(values, lambda k: (np.eye(2), 0.01 * np.eye(2), np.diag([1.0, k])))
    f = tr.frequencies
    w1 = np.sqrt(values) / (2 * np.pi)
    assert np.allclose(np.sort(f, axis=1), np.sort(np.c_[np.full(61, 1 / (2 * np.pi)), w1], axis=1), rtol=1e-3)
    # one track is the constant mode all along
    const = [k for k in range(2) if np.ptp(f[:, k]) < 1e-3]
    assert len(const) == 1
    assert np.all(tr.continuity[1:] > 0.99)


def test_paper_crossings_agree_with_the_exact_route():
    from brakesqueal import crossings
    from brakesqueal import Axis
    from brakesqueal.model import ParameterSpace

    tr = modes_along(resolve_space(preset="paper-fig2", sets=["mu=0.5"]), "k_ip", 1e5, 1e10, num=120, log=True)
    exact = crossings(ParameterSpace.from_preset("paper-fig2", {"mu": 0.5}), Axis("k_ip", 1e5, 1e10, 2, True))
    got = sorted(c["value"] for c in tr.crossings)
    want = sorted(v for v, _ in exact.crossings)
    # bisection on eigenvalue signs: accurate to the eigenvalues' rounding near Re = 0 (~1e-7 relative here)
    assert np.allclose(got, want, rtol=1e-6)


def test_modes_command_json_and_bad_input(tmp_path, capsys):
    rc = main(["modes", "--along", "m_c=0.1:20", "--model", "eight-dof", "--num", "30", "--format", "json"])
    out = capsys.readouterr()
    assert rc == 0, out.err
    data = json.loads(out.out)
    assert data["model"] == "eight-dof" and isinstance(data["crossings"], list)
    rc = main(["modes", "--along", "k_ip=1e5:1e10:log", "--plot", str(tmp_path / "no" / "m.png")])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "does not exist" in err
    rc = main(["modes", "--along", "kip=1:2"])
    err = capsys.readouterr().err
    assert rc == 2 and "did you mean 'k_ip'" in err


@pytest.mark.slow
def test_a_path_on_which_the_pads_states_come_and_go():
    """paper-fig3 with h10 = 0.012 along mu1 in [0, 1.2] (the explorer's slider range): at mu1 = 0 the silent
    motion keeps no pad state, elsewhere both pads' rates are kept (2n + 2 first-order states).  The tracking
    compared vectors of different lengths and raised a NumPy ValueError (found through the explorer's root
    locus); it now compares their shared mechanical part, and every path point's eigenvalues are on a track."""
    from brakesqueal import linearize

    space = resolve_space(None, "paper-fig3", None, ["h10=0.012"])
    values = np.linspace(0.0, 1.2, 60)
    kept = {len(linearize(space.resolve({"mu1": float(v)})).pad_states) for v in values}
    assert len(kept) > 1, kept  # the path does mix both forms
    tr = modes_along(space, "mu1", 0.0, 1.2, num=60, log=False)
    lam = np.asarray(tr.eigenvalues)
    assert lam.shape[0] == values.size
    for i, v in enumerate(values):
        lm = linearize(space.resolve({"mu1": float(v)}))
        ref = np.asarray(lm.eigenvalues)
        ref = ref[ref.imag >= -1e-12 * np.maximum(np.abs(ref), 1.0)]
        got = lam[i][np.isfinite(lam[i])]
        assert got.size == ref.size
