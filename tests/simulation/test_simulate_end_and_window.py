"""The end time a run reports, and the summary of an estimation window too short for a frequency."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from brakesqueal.cli import main
from brakesqueal.model import get_preset
from brakesqueal import simulate
from brakesqueal.simulation.trajectory import summarize


@pytest.fixture(scope="module")
def params():
    return get_preset("paper-fig2").resolve({})


def test_end_time_is_where_the_integration_ended_not_the_last_sample(params):
    # 10 output samples per second: the last one (0.01 s) lies before the end time 0.0105 s
    tr = simulate(params, 0.0105, sample_rate=100.0)
    assert tr.status == "finished" and tr.t[-1] == pytest.approx(0.01)
    assert tr.t_end_reached == 0.0105


@pytest.mark.slow
def test_end_time_of_a_contact_loss_is_the_event_time(capsys):
    """The run of the defect: the message says t = 33.4809 s, t_end_reached said 33.0 (the last sample)."""
    rc = main(["simulate", "--t-end", "40", "--sample-rate", "1", "--format", "json", "--no-progress"])
    d = json.loads(capsys.readouterr().out)
    assert rc == 0 and d["status"] == "contact-loss"
    t_msg = float(d["message"].split("t = ")[1].split(" s")[0])
    assert d["t_end_reached"] == pytest.approx(t_msg, abs=1e-4) and d["t_end_reached"] > 33.4


def test_window_shorter_than_a_period_has_no_frequency(params, capsys):
    tr = simulate(params, 1e-9)
    s = tr.summary
    assert s.estimate_status == "window-shorter-than-a-period" and s.regime == "unknown"
    assert math.isnan(s.frequency_hz) and math.isnan(s.growth_rate) and math.isnan(s.frequency_stderr)
    d = s.to_dict()
    assert d["frequency_hz"] is None and d["frequency_stderr"] is None and d["growth_rate"] is None
    assert any("shorter than one period" in w for w in s.warnings)
    assert tr.t_end_reached == 1e-9
    rc = main(["simulate", "--t-end", "1e-9", "--format", "json", "--no-progress"])
    out = capsys.readouterr()
    assert rc == 0 and json.loads(out.out)["estimate_status"] == "window-shorter-than-a-period"
    assert "warning: the estimation window" in out.err and "nan" not in out.out.lower()


def test_summarize_decides_by_the_number_of_periods_in_the_window(rng):
    """A synthetic decaying oscillation at 100 Hz (no linear model: the matrix pencil): half a period is not
    enough, three periods are and give the frequency."""
    f, g = 100.0, -3.0

    def record(periods: float) -> tuple[np.ndarray, np.ndarray]:
        t = np.linspace(0.0, periods / f, 400)
        q = np.exp(g * t) * np.cos(2 * np.pi * f * t + 0.3)
        dq = np.gradient(q, t)
        return t, np.column_stack([q, 0.5 * q, dq, 0.5 * dq]) * 1e-5

    short = summarize("finished", *record(0.5), None)
    assert short.estimate_status == "window-shorter-than-a-period" and math.isnan(short.frequency_hz)
    ok = summarize("finished", *record(3.0), None)
    assert ok.estimate_status == "ok" and ok.frequency_hz == pytest.approx(f, rel=1e-3)
    few = summarize("finished", *[a[:10] for a in record(3.0)], None)
    assert few.estimate_status == "too-few-samples" and math.isnan(few.frequency_hz)


def test_matrix_pencil_drops_poles_that_overflow_over_the_window():
    """np.gradient's one-sided ends give the pencil a spurious pole growing by more than 1e300 over the window;
    its amplitude fit was non-finite and LAPACK's least squares never returned (summarize hung)."""
    from brakesqueal.simulation.estimate import matrix_pencil

    t = np.linspace(0.0, 0.005, 400)
    q = np.exp(-3.0 * t) * np.cos(2 * np.pi * 100.0 * t + 0.3)
    dq = np.gradient(q, t)
    pm = matrix_pencil(t, np.column_stack([q, 0.5 * q, dq, 0.5 * dq]) * 1e-5)
    assert np.all(pm.eigenvalues.real * (t[-1] - t[0]) < 600.0)
    assert np.all(np.isfinite(pm.eigenvalues))
