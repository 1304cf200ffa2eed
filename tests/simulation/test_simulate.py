"""Verification of the nonlinear time simulation (brakesqueal.simulation)."""

from __future__ import annotations

import json
import math
import wave

import numpy as np
import pytest

from brakesqueal import linearize
from brakesqueal.errors import ParameterError
from brakesqueal.model import get_preset
from brakesqueal import simulate

# least-stable mode: Re(lambda) = +3.37 1/s (unstable) and -1.01 1/s (stable), both at ~1739 Hz
UNSTABLE = {"mu": 1.0, "h": 0.05}
STABLE = {"mu": 0.5, "d1": 20.0, "d2": 20.0}


def _modal_start(params, amp=1e-5):
    """Initial deviation along the real part of the least-stable eigenvector (one mode, no beating)."""
    lm = linearize(params)
    lam = lm.eigenvalues[0]
    w, V = np.linalg.eig(lm.A)
    v = V[:, np.argmin(abs(w - lam))]
    v = v / v[np.argmax(abs(v[:2]))]
    return lam, np.real(v) * amp


@pytest.mark.parametrize("overrides", [UNSTABLE, STABLE], ids=["unstable", "stable"])
def test_growth_and_frequency_match_linear_eigenvalue(overrides):
    params = get_preset("paper-fig2").resolve(overrides)
    lam, dx = _modal_start(params)
    tr = simulate(params, 0.5, perturbation=dx)
    assert tr.status == "finished", tr.message
    s = tr.summary
    assert abs(s.growth_rate - lam.real) <= 0.02 * abs(lam.real)
    assert abs(2 * math.pi * s.frequency_hz - lam.imag) <= 1e-3 * lam.imag
    assert s.limit_cycle_amplitude is None


def test_energy_conserved_without_friction_and_damping():
    params = get_preset("paper-fig2").resolve().replace(mu1=0.0, mu2=0.0, d_t=0.0, d1=0.0, d2=0.0)
    tr = simulate(params, 0.6, perturbation=[1e-5, 5e-6], rtol=1e-11, events="off", sample_rate=20000)
    assert tr.status == "finished"
    assert tr.summary.frequency_hz * 0.6 > 1000  # at least 1000 periods
    e = tr.energy()
    scale = e["T2"].max()
    drift = np.abs(e["E"] - e["E"][0]).max() / scale
    assert drift < 1e-6
    # negative control: with support damping the same quantity decays measurably
    damped = simulate(params.replace(d_t=0.1), 0.2, perturbation=[1e-5, 5e-6], events="off", sample_rate=20000)
    ed = damped.energy()
    assert (ed["E"][0] - ed["E"][-1]) / ed["T2"].max() > 1e-3


def test_integrators_agree_within_tolerance():
    params = get_preset("paper-fig2").resolve(UNSTABLE)
    ref = simulate(params, 0.02, rtol=1e-12)
    scale = np.abs(ref.y).max(axis=0)
    for method, rtol in (("DOP853-jit", 1e-9), ("DOP853", 1e-9), ("RK45", 1e-8), ("LSODA", 1e-9)):
        tr = simulate(params, 0.02, method=method, rtol=rtol)
        assert tr.status == "finished"
        err = np.abs(tr.y - ref.y).max(axis=0) / scale
        assert err.max() < 1e4 * rtol, (method, err)
    # and the errors are not zero: the comparison can fail
    loose = simulate(params, 0.02, method="RK45", rtol=1e-3)
    assert (np.abs(loose.y - ref.y).max(axis=0) / scale).max() > 1e-4


def test_contact_loss_stops_with_partial_trajectory():
    params = get_preset("paper-fig2").resolve({"mu": 1.0, "h": 0.05})
    tr = simulate(params, 3.0, perturbation=[2e-3, 0.0], sample_rate=20000)
    assert tr.status in ("contact-loss", "sliding-reversal")
    assert tr.t_event is not None and 0 < tr.t_event < 3.0
    assert tr.t[-1] <= tr.t_event < tr.t[-1] + 1 / 20000 + 1e-12
    fn = tr.normal_forces
    assert np.all(fn[:-1] > 0)
    if tr.status == "contact-loss":
        from brakesqueal import simulation_model

        c = simulation_model("paper").contact_at(params, tr.y_event)  # (pads, CONTACT_FIELDS)
        assert c[:, 0].min() == pytest.approx(0.0, abs=1e-6 * params.N0)
        assert tr.event_pad == ("1", "2")[int(np.argmin(c[:, 0]))]


@pytest.mark.slow
def test_scipy_event_agrees_with_compiled_event():
    params = get_preset("paper-fig2").resolve({"mu": 1.0, "h": 0.05})
    # the compiled integrator also looks inside each step (dense output), so it agrees with a
    # small-step SciPy run; SciPy checks events at step ends only and may miss a brief dip
    a = simulate(params, 3.0, perturbation=[2e-3, 0.0], sample_rate=5000, rtol=1e-10)
    b = simulate(params, 3.0, perturbation=[2e-3, 0.0], sample_rate=5000, rtol=1e-10, method="RK45")
    assert a.status == b.status
    assert a.t_event == pytest.approx(b.t_event, rel=1e-6)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"t_span": 0.0}, "end time"),
        ({"t_span": -1.0}, "end time"),
        ({"x0": [math.nan, 0, 0, 0]}, "finite"),
        ({"perturbation": [math.inf, 0]}, "finite"),
        ({"rtol": 1e-20}, "rtol"),
        ({"rtol": 0.5}, "rtol"),
        ({"atol": -1.0}, "atol"),
        ({"method": "Euler"}, "method"),
        ({"perturbation": [0.05, 0.0]}, "out of contact"),
    ],
)
def test_bad_input(kwargs, match):
    params = get_preset("paper-fig2").resolve()
    kw = {"t_span": 0.01, **kwargs}
    t_span = kw.pop("t_span")
    with pytest.raises(ParameterError, match=match):
        simulate(params, t_span, **kw)


def test_failure_keeps_partial_trajectory():
    params = get_preset("paper-fig2").resolve()
    tr = simulate(params, 0.05, max_steps=200, sample_rate=20000)
    assert tr.status == "failed" and "max_steps" in tr.message
    assert 1 < tr.t.size < 1001 and np.all(np.isfinite(tr.y))


def test_exports(tmp_path):
    params = get_preset("paper-fig2").resolve()
    tr = simulate(params, 0.01)
    ds = tr.to_xarray()
    assert ds["q"].dims == ("time", "dof") and ds.sizes["time"] == tr.t.size
    assert ds.attrs["status"] == "finished"
    nc = tmp_path / "sim.nc"
    tr.to_netcdf(str(nc))
    import xarray as xr

    back = xr.load_dataset(nc)
    np.testing.assert_allclose(back["q"].values, tr.y[:, :2])
    assert json.loads(back.attrs["parameters"])["mu1"] == 0.5
    wav = tmp_path / "s.wav"
    n = tr.to_wav(str(wav))
    with wave.open(str(wav)) as w:
        assert w.getframerate() == 44100 and w.getnframes() == n and w.getsampwidth() == 2
    fig = tr.plot()
    assert len(fig.axes) == 3
