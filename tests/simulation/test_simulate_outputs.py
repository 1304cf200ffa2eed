"""``simulate``'s outputs say how long the run lasted and why, with per-coordinate units (issue 29, item 4)."""

from __future__ import annotations

import json
import wave
from dataclasses import replace

import numpy as np
import pytest
import xarray as xr
from matplotlib.figure import Figure

from brakesqueal.cli import main

ARGS = ["simulate", "--set", "mu=1", "--set", "h=0.05", "--q0", "2.2e-3,0", "--t-end", "0.2", "--rtol", "1e-6",
        "--sample-rate", "8000", "--no-progress"]


@pytest.fixture(scope="module")
def early_stop(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("sim")
    figs: list[Figure] = []
    orig = Figure.savefig
    mp = pytest.MonkeyPatch()
    mp.setattr(Figure, "savefig", lambda self, *a, **k: (figs.append(self), orig(self, *a, **k))[1])
    import contextlib
    import io

    out, err = io.StringIO(), io.StringIO()
    paths = {k: tmp / f"x.{k}" for k in ("wav", "png", "nc")}
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            rc = main([*ARGS, "--format", "json", "--wav", str(paths["wav"]), "--plot", str(paths["png"]),
                       "--out", str(paths["nc"])])
    finally:
        mp.undo()
    assert rc == 0
    return json.loads(out.getvalue()), err.getvalue(), paths, figs


def test_early_stop_is_explained_everywhere(early_stop):
    data, err, paths, figs = early_stop
    assert data["status"] == "contact-loss"
    d = data["duration_s"]
    assert 0.01 < d < 0.1 and d == pytest.approx(data["t_end_reached"])
    assert data["stop_reason"].startswith("stopped early after") and "of 0.2 s" in data["stop_reason"]
    assert "lost contact" in data["stop_reason"]
    with wave.open(str(paths["wav"])) as w:
        wav_s = w.getnframes() / w.getframerate()
    assert wav_s == pytest.approx(d, abs=2e-3) and data["wav_s"] == pytest.approx(wav_s)
    note = [s for s in err.splitlines() if s.startswith("brakesqueal: note:")]
    assert len(note) == 1 and "stopped early" in note[0] and "lost contact" in note[0]
    assert f"{wav_s:.4g} s of audio" in note[0]
    ds = xr.load_dataset(paths["nc"])
    assert ds.attrs["stop_reason"] == data["stop_reason"] and ds.attrs["duration_s"] == pytest.approx(d)
    (fig,) = figs
    title = fig.axes[0].get_title(loc="left")
    assert "stopped early" in title and "lost contact" in title
    assert data["amplitude_final_by_coordinate"]["q1"]["unit"] == "rad"


def test_plot_shows_the_coordinate_that_carries_the_motion():
    """q2 carries the motion (q1, q2 swapped): phase portrait, spectrum and amplitude show q2, in rad;
    a pad displacement in metres is never labelled in rad."""
    from brakesqueal import simulate
    from brakesqueal.model.options import resolve_space

    p = resolve_space(None, None, None, ["mu=1", "h=0.05"]).resolve({})
    tr = simulate(p, 0.01, perturbation=[1e-4, 0.0], rtol=1e-6, sample_rate=8000)
    n = tr.n
    perm = list(range(tr.y.shape[1]))
    perm[0], perm[1], perm[n], perm[n + 1] = 1, 0, n + 1, n
    sw = replace(tr, y=tr.y[:, perm], q0=tr.q0[[1, 0, *range(2, n)]])
    sw = replace(sw, y=sw.y.copy())
    sw.y[:, 0] = sw.q0[0] + 1e-3 * (sw.y[:, 0] - sw.q0[0])  # q1 hardly moves
    assert sw.main_coordinate == 1
    fig = sw.plot()
    ax_t, ax_p, ax_s = fig.axes
    assert ax_p.get_xlabel() == "q2 − q2₀ [rad]" and ax_p.get_ylabel() == "dq2/d$t$ [rad/s]"
    assert "q2" in ax_p.get_title(loc="left") and "q2" in ax_s.get_title(loc="left")
    assert ax_s.get_ylabel() == "|q2| [rad]"
    amp = sw.final_amplitudes()
    assert f"final amplitude of q2 = {amp['q2']:.3g} rad" in ax_t.get_title(loc="left")
    assert "ran the whole 10 ms" in ax_t.get_title(loc="left")
    assert amp["q1"] < 0.01 * amp["q2"]
    assert np.isfinite(list(amp.values())).all()

