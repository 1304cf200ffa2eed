"""Regularised stick-slip of massless pads: the friction law ``stick`` and ``regularised_pads(..., stick_speed=V)``.

The law is ``mu(v) = mu v / sqrt(v^2 + V^2) - slope v``, so the friction force
``mu(|v_r|) F_n v_r / |v_r| = F_n (mu / sqrt(|v_r|^2 + V^2) - slope) v_r`` is smooth through ``v_r = 0``.
References made here: the law's limits and continuity with SymPy (an independent expansion); the
simulation's dependence on ``V`` against that expansion (no sticking: the stick law differs from the rising
law ``mu - slope v`` by ``mu V^2 / (2 v^2)``, so halving ``V`` divides the difference by 4); with sticking,
convergence as ``V -> 0`` and the sticking pad's relative speed bounded by the law's creep bound.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from brakesqueal import resolve_space
from brakesqueal.cli import main
from brakesqueal.errors import ParameterError
from brakesqueal.model.friction import LAWS
from brakesqueal.model.options import MAX_STICK_SPEED, regularised_pads
from brakesqueal import simulate

#: paper-fig3 with soft pads (a pad's sliding reverses on the cycles; docs/nonlinear.md)
SETS = ["mu1=0.5", "mu2=0.5", "k_ip1=1e6", "k_ip2=1e6"]
SLOPE = 1e-4


def test_the_law_is_coulomb_away_from_stick_and_smooth_through_zero():
    v, mu, V, s = sp.symbols("v mu V s", positive=True)
    law = LAWS["stick"]
    m = law.formula(sp, v, {"mu": mu, "v_reg": V, "slope": -s})  # a rising slope s
    # far from stick: mu(v) = mu + s v - mu V^2 / (2 v^2) + O(V^4)
    series = sp.series(m.subs(V, sp.Symbol("e") * v), sp.Symbol("e"), 0, 4).removeO()
    assert sp.simplify(series - (mu + s * v - mu * sp.Symbol("e") ** 2 / 2)) == 0
    # the force factor mu(v) / v is finite at v = 0: the force F_n (mu(v)/v) v_r is continuous through v_r = 0
    assert sp.limit(m / v, v, 0) == mu / V + s
    # rising everywhere for s >= 0: a massless pad's balance has one root for every spring force
    assert sp.simplify(sp.diff(m, v) - (mu * V**2 / (v**2 + V**2) ** sp.Rational(3, 2) + s)) == 0
    assert "v_reg" in law.fields and law.rate_dependent
    assert law.text == "mu(v) = mu * v / sqrt(v^2 + v_reg^2) - slope * v"


def test_regularised_pads_with_a_stick_speed():
    space = resolve_space(preset="paper-fig3", sets=SETS)
    spec = regularised_pads(space, SLOPE, 2e-3).resolve({}).model
    assert spec.name == "paper+stick-slip-pads"
    for pad in spec.pads:
        assert pad.friction.law == "stick"
        assert pad.friction.values() == {"mu": pad.friction.mu, "v_reg": 2e-3, "slope": -SLOPE}
    assert regularised_pads(space, SLOPE).resolve({}).model.pads[0].friction.law == "linear"
    for bad in (0.0, -1e-3, MAX_STICK_SPEED * 2, float("nan"), "x"):
        with pytest.raises(ParameterError, match=r"'stick_speed' must be in \(0, 1\] m/s"):
            regularised_pads(space, SLOPE, bad)


def test_stick_speed_needs_pad_slope_on_the_command_line(capsys):
    assert main(["simulate", "--set", "k_ip=1e6", "--t-end", "0.001", "--stick-speed", "1e-3"]) == 2
    assert "--stick-speed regularises the pads of --pad-slope" in capsys.readouterr().err
    assert main(["cycles", "--set", "k_ip=1e6", "--along", "Omega=60:120", "--pad-slope", "1e-4",
                 "--stick-speed", "2"]) == 2
    assert "'--stick-speed' must be in (0, 1] m/s" in capsys.readouterr().err


def _run(vs, omega, t_end, perturbation):
    space = resolve_space(preset="paper-fig3", sets=[*SETS, f"Omega={omega}"])
    return simulate(regularised_pads(space, SLOPE, vs).resolve({}), t_end, perturbation=perturbation,
                    events="continue", sample_rate=200_000.0)


@pytest.mark.slow
def test_without_sticking_the_law_differs_from_the_rising_law_by_v_reg_squared():
    """Omega = 90 rad/s (Omega r = 11.7 m/s), a small vibration: the pads never come near stick."""
    kick = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
    ref = _run(None, 90, 0.002, kick)
    diffs = []
    for vs in (0.4, 0.2):
        tr = _run(vs, 90, 0.002, kick)
        assert tr.status == "finished" and not tr.event_times
        assert np.all(np.abs(tr.contact[:, :, 1]) > 5.0)  # sliding at several m/s throughout
        diffs.append(np.abs(tr.y[:, :4] - ref.y[:, :4]).max())
    assert 3.5 < diffs[0] / diffs[1] < 4.5, diffs  # O(V^2)


@pytest.mark.slow
def test_a_pad_that_would_stick_creeps_at_the_regularisation_speed_and_the_runs_converge():
    """Omega = 10 rad/s (Omega r = 1.3 m/s) and a kick of 20 rad/s: the pads' tangential rate reaches the
    sliding speed once per period.  With the rising law alone a pad's sliding velocity then sweeps through
    reversal (recorded events: the friction force cannot fall below mu F_n except by turning); with
    regularised stick-slip the pads stick instead, creeping at a speed proportional to V (the law's creep
    bound V f / sqrt((mu F_n)^2 - f^2) is 0.58 V at half the friction limit), never reversing, and the runs
    converge as V -> 0 (at least at first order)."""
    kick = [0.0, 0.0, 20.0, 0.0, 0.0, 0.0]
    plain = _run(None, 10, 0.005, kick)
    assert plain.status == "finished" and plain.event_times  # sliding reversals without stick regularisation
    ys, creep = [], []
    for vs in (2e-3, 1e-3, 5e-4):
        tr = _run(vs, 10, 0.005, kick)
        assert tr.status == "finished" and not np.isnan(tr.contact).any() and not np.isnan(tr.l).any()
        vr = tr.contact[:, :, 1:4]
        speed = np.linalg.norm(vr, axis=2)
        # the pads stick briefly in every period of the vibration (1.74 kHz; about 10 us each at these V)
        stuck = np.flatnonzero((speed < 2 * vs).any(axis=1))
        assert stuck.size >= 5 and np.ptp(tr.t[stuck]) > 0.5 * tr.t[-1]
        direction = vr.mean(axis=0) / np.linalg.norm(vr.mean(axis=0), axis=1)[:, None]
        along = np.einsum("tpk,pk->tp", vr, direction)
        assert along.min() > 0 and not tr.event_times  # no reversal: they stick instead
        creep.append(speed.min() / vs)
        ys.append(tr.y[:, :4])
    assert all(0.3 < c < 1.0 for c in creep), creep
    d1, d2 = np.abs(ys[0] - ys[1]).max(axis=0), np.abs(ys[1] - ys[2]).max(axis=0)
    assert np.all(d1 / d2 > 1.8), d1 / d2


@pytest.mark.slow
@pytest.mark.parametrize("vs", [None, 1e-3])
def test_the_pad_solve_converges_from_any_warm_start(vs):
    """Near stick a pad's balance is nearly a step in its rate and Newton from a far warm start overshoots
    (the post-processing once returned NaN for 40 % of the samples): the bracketed fallback finds a root
    from any start.  Random states (tilts, tilt rates up to the kick above, pad deformations) and random warm
    starts; each returned rate is checked by evaluating the balance again: the remaining Newton step is within
    the solve's tolerance and the balance changes sign across the root."""
    from brakesqueal import simulation_model

    space = regularised_pads(resolve_space(preset="paper-fig3", sets=[*SETS, "Omega=10"]), SLOPE, vs)
    params = space.resolve({})
    sim = simulation_model(params.model)
    p = sim.parameter_vector(params)
    st = sim.silent(params)
    rng = np.random.default_rng(7)
    g = np.empty(5)
    for _ in range(200):
        y = np.concatenate([rng.uniform(-1e-3, 1e-3, 2), rng.uniform(-20, 20, 2), rng.uniform(-4e-4, 4e-4, 2)])
        l, dl = np.zeros(2), rng.uniform(-100, 100, 2)
        assert sim.kernels.solve_pads(y, l, dl, p, st.ztol, g), y
        root = dl.copy()
        sim.kernels.pad_balance(y, l, root.copy(), p, g)
        assert np.all(np.abs(g[:2] / g[2:4]) <= 1e-12 * np.abs(root) + 2 * st.ztol + 1e-300)
        for j in range(2):
            side = []
            for dz in (-1e-6, 1e-6):
                d = root.copy()
                d[j] += dz * (1 + abs(root[j]))
                sim.kernels.pad_balance(y, l, d, p, g)
                side.append(g[j])
            assert side[0] * side[1] < 0, (y, root)


@pytest.mark.slow
@pytest.mark.parametrize("method", ["DOP853-jit", "RK45"])
def test_with_stick_slip_events_stop_only_at_contact_loss(method):
    """events="stop" (the default): the rising-law pads' run stops at its first sliding reversal (at a near
    stick their sliding velocity turns through reversal; the end of that model's validity), while with
    regularised stick-slip the same start sticks and runs to the end.  A start that loses contact: the stick-law
    pads' sliding reverses just before (recorded, passed) and the run stops at the contact loss, where the
    rising law's run (events recorded) has it."""
    space = resolve_space(preset="paper-fig3", sets=[*SETS, "Omega=1"])
    t_end = 0.002
    kick = [0.0, 0.0, 30.0, 0.0, 0.0, 0.0]  # F_n stays above 850 N
    if method == "DOP853-jit":  # (solve_ivp checks events at its step ends only and misses these brief dips)
        plain = simulate(regularised_pads(space, SLOPE).resolve({}), t_end, perturbation=kick)
        assert plain.status == "sliding-reversal" and plain.t_event < t_end
        stick = simulate(regularised_pads(space, SLOPE, 1e-3).resolve({}), t_end, perturbation=kick)
        assert stick.status == "finished" and not stick.event_times
    lift = [0.0, 0.0, 60.0, 0.0, 0.0, 0.0]  # the tilt reaches 5.5e-3 rad: a pad's F_n falls through 0 at 70 us
    ref = simulate(regularised_pads(space, SLOPE).resolve({}), t_end, perturbation=lift, method=method,
                   events="continue")
    t_loss = min(v[0] for k, v in ref.event_times.items() if k.startswith("contact-loss"))
    tr = simulate(regularised_pads(space, SLOPE, 1e-3).resolve({}), t_end, perturbation=lift, method=method)
    assert tr.status == "contact-loss" and tr.t_event == pytest.approx(t_loss, rel=1e-5)
    # as F_n -> 0 the friction can no longer hold the pad's spring: it slips forward (a true reversal),
    # which is recorded and passed (a second turn located at the contact loss itself, where F_n = 0 leaves the pad
    # no friction, may be recorded too: rounding decides)
    rev = [t for k, v in tr.event_times.items() if k.startswith("sliding-reversal") for t in v]
    assert all(t <= tr.t_event for t in rev) and (rev or method != "DOP853-jit")
    assert not rev or min(rev) < tr.t_event


def test_reversal_is_ordinary_motion_only_when_every_pad_has_regularised_stick_slip():
    """One rule for the simulation and the branches (``stick_slip_everywhere``): a model with one stick-law pad
    and one Coulomb pad keeps the end of validity at a reversal (the Coulomb pad would stick)."""
    from dataclasses import replace

    from brakesqueal.model.components import FrictionLaw
    from brakesqueal.model.options import stick_slip_everywhere

    space = resolve_space(preset="paper-fig3", sets=SETS)
    assert not stick_slip_everywhere(space.resolve({}).model)
    stick = regularised_pads(space, SLOPE, 1e-3).resolve({}).model
    assert stick_slip_everywhere(stick)
    mixed = replace(stick, pads=(stick.pads[0], replace(stick.pads[1], friction=FrictionLaw("coulomb", "mu2"))))
    assert not stick_slip_everywhere(mixed)
    assert not stick_slip_everywhere(regularised_pads(space, SLOPE).resolve({}).model)
