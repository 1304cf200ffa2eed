"""Hopf points with the pads' true tangential dynamics (nonlinear.implicit.exact_lyapunov).

Independent checks:
* on a model whose pads have a regular first-order dynamics (a rising friction law
  ``mu(v) = mu1 + |s| v``: the pad's rate is a state of an explicit ODE), the normal form of the implicit
  equations equals Kuznetsov's formula on that ODE (``first_lyapunov`` of ``model_system``, a different
  route: the explicit vector field, its generated Jacobian, the pads eliminated by implicit differentiation);
* as the friction slope tends to 0 that ODE's l1 tends to the Coulomb model's l1 of this module (the pad
  becomes infinitely fast but keeps its rate), and not to the quasi-static pad's l1;
* with rigid pads (no pad unknown) both routes describe the same equations and agree;
* the leading-order contact loss prediction against the located one of the limit-cycle branch.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from brakesqueal import Axis
from brakesqueal.cli import main
from brakesqueal.model import MODELS, ParameterSpace
from brakesqueal.model.io import model_to_toml
from brakesqueal.model.options import resolve_space
from brakesqueal.nonlinear import find_periodic_orbit, first_lyapunov
from brakesqueal import exact_lyapunov
from brakesqueal import hopf_points, model_system

K_IP = 1e5
ONSET = 3.3533  # the Coulomb model's Hopf point near 3.35 rad/s at k_ip = 1e5 (refined by the code)


@pytest.fixture(scope="module")
def rising_friction_model(tmp_path_factory):
    """The paper's model with the linear law ``mu1 - s v`` at both pads (``s < 0``: rising friction)."""
    text = model_to_toml(resolve_space(None, None, None, []).resolve({}).model)
    text = text[:text.index("[presets")] if "[presets" in text else text
    text = text.replace('name = "paper"', 'name = "paper-rising"', 1)
    for pad in ("mu1", "mu2"):
        text = text.replace(f'law = "coulomb", mu = "{pad}"', f'law = "linear", mu = "{pad}", slope = "s"')
    text = text.replace("\nOmega = ", "\ns = -0.001\nOmega = ", 1)
    path = tmp_path_factory.mktemp("models") / "rising.toml"
    path.write_text(text)
    return str(path)


def _ode_l1(space, p0, omega):
    system = model_system(space, "Omega")
    y0 = system.simulation_model.silent(space.resolve({"Omega": p0})).y
    return first_lyapunov(system, y0, p0, refine=True, omega=omega)


@pytest.mark.slow
def test_implicit_normal_form_equals_the_ode_route_for_regular_pads(rising_friction_model):
    space = resolve_space(rising_friction_model, None, None, [f"k_ip1={K_IP}", f"k_ip2={K_IP}", "s=-1e-3"])
    ex = exact_lyapunov(space, "Omega", 4.19).hopf
    ode = _ode_l1(space, ex.p0, ex.omega0)
    assert ex.p0 == pytest.approx(ode.p0, rel=1e-8)  # Re lambda = 0 to ~1e-13 |lambda| in both routes
    assert ex.omega0 == pytest.approx(ode.omega0, rel=1e-9)
    assert ex.state_names == ode.state_names  # (q, dq, l1, l2): the pads' deformations are states in both
    tol = 10 * (ex.l1_error + ode.l1_error) + 1e-5 * abs(ode.l1)
    assert abs(ex.l1 - ode.l1) <= tol, (ex.l1, ode.l1)
    assert ex.dlambda_dp == pytest.approx(ode.dlambda_dp, rel=1e-6)
    np.testing.assert_allclose(ex.amplitude_coefficients, ode.amplitude_coefficients, rtol=1e-4)


@pytest.mark.slow
def test_coulomb_pads_are_the_limit_of_vanishing_friction_slope(rising_friction_model):
    coulomb = resolve_space(None, None, None, [f"k_ip={K_IP}"])
    pts = hopf_points(coulomb, Axis("Omega", 1.0, 10.0))
    assert len(pts) == 1
    hp = pts[0]
    exact, quasi = hp.hopf, hp.simulated
    assert exact is not None and quasi is not None and hp.value == pytest.approx(ONSET, rel=1e-4)
    errs = []
    for s in (1e-4, 1e-5):
        space = resolve_space(rising_friction_model, None, None, [f"k_ip1={K_IP}", f"k_ip2={K_IP}", f"s={-s}"])
        ode = _ode_l1(space, exact.p0, exact.omega0)
        errs.append(abs(ode.l1 - exact.l1) / abs(exact.l1))
    assert errs[1] < 0.3 * errs[0] and errs[1] < 2e-2, errs  # O(s) convergence to the Coulomb pads' l1
    # the quasi-static pad misses it: here even the sign (issue #14's first design fact)
    assert abs(quasi.l1 - exact.l1) > 10 * abs(exact.l1) * errs[1]
    assert exact.criticality == "supercritical"


def test_rigid_pads_both_routes_agree():
    space = ParameterSpace.from_preset("paper-fig3", {"mu1": 0.5, "mu2": 0.5, "k_ip": math.inf})
    hp = hopf_points(space, Axis("Omega", 1.0, 1e3, log=True))[0]
    assert hp.simulated is None and hp.hopf is not None  # the simulated equations are exact here
    ode = _ode_l1(space, hp.hopf.p0, hp.hopf.omega0)
    assert abs(hp.hopf.l1 - ode.l1) <= 10 * (hp.hopf.l1_error + ode.l1_error) + 1e-6 * abs(ode.l1)
    assert hp.hopf.p0 == pytest.approx(35.601027692919985, rel=1e-10)  # the exact crossing (README, Fig. 3)
    np.testing.assert_allclose(hp.hopf.amplitude_coefficients, ode.amplitude_coefficients, rtol=1e-4)


def test_soft_pads_change_l1_and_the_outputs_say_so(capsys):
    """k_ip = 1e6: the pads' rate changes l1 by more than an order of magnitude, same sign (issue #14)."""
    assert main(["hopf", "--set", "k_ip=1e6", "--along", "Omega=10:200", "--format", "json"]) == 0
    d = json.loads(capsys.readouterr().out)
    (c,) = d["crossings"]
    h, hs = c["hopf"], c["hopf_simulated"]
    assert hs is not None and "quasi-static" in c["message"]
    assert h["l1"] < 0 and hs["l1"] < 0 and abs(h["l1"]) > 10 * abs(hs["l1"])
    assert h["p0"] == pytest.approx(hs["p0"], rel=1e-9)  # same linearization, same onset
    pred = c["predicted"]
    # leading-order predictions on the side where the cycles exist
    assert pred["sliding_reversal"] > h["p0"] and pred["contact_loss"] > h["p0"]
    assert 1e-4 < pred["tilt_at_sliding_reversal"] < 1e-2  # "tilt amplitudes of about 1e-3 rad"
    assert main(["hopf", "--set", "k_ip=1e6", "--along", "Omega=10:200"]) == 0
    out = capsys.readouterr().out
    assert "sliding reverses" in out and "quasi-static" in out


def test_bad_parameter_is_named():
    space = resolve_space(None, None, None, [])
    with pytest.raises(Exception, match="Omgea"):
        exact_lyapunov(space, "Omgea", 37.0)
    with pytest.raises(Exception, match="finite"):
        exact_lyapunov(space, "Omega", math.nan)


@pytest.mark.slow
@pytest.mark.parametrize("name", list(MODELS))
def test_every_built_in_model_against_the_ode_route(name):
    """Where the simulated equations are exact (no quasi-static pad with a finite k_ip), both routes agree."""
    space = ParameterSpace.from_preset(name)
    axis = Axis("slope", 0.0, 0.02) if name == "belt" else Axis("Omega", 1.0, 1e3, log=True)
    pts = [hp for hp in hopf_points(space, axis) if hp.hopf is not None]
    assert pts, name
    for hp in pts:
        ex = hp.hopf
        ode = hp.simulated if hp.simulated is not None else _ode_l1_along(space, axis.name, ex)
        assert ex.p0 == pytest.approx(ode.p0, rel=1e-8) and ex.omega0 == pytest.approx(ode.omega0, rel=1e-9)
        if hp.simulated is None:
            tol = 10 * (ex.l1_error + ode.l1_error) + 1e-4 * abs(ode.l1)
            assert abs(ex.l1 - ode.l1) <= tol, (name, ex.l1, ode.l1)
            assert ex.criticality == ode.criticality


def _ode_l1_along(space, name, ex):
    system = model_system(space, name)
    y0 = system.simulation_model.silent(space.resolve({name: ex.p0})).y
    return first_lyapunov(system, y0, ex.p0, refine=True, omega=ex.omega0)


def test_crossings_and_critical_speed_gain_the_hopf_fields(capsys):
    """`crossings --hopf` and `critical-speed --hopf` give the `hopf` command's fields for every crossing."""
    assert main(["hopf", "--along", "Omega=1:1e4:log", "--format", "json"]) == 0
    ref = json.loads(capsys.readouterr().out)["crossings"]
    assert main(["crossings", "--along", "Omega=1:1e4:log", "--hopf", "--format", "json"]) == 0
    got = json.loads(capsys.readouterr().out)["crossings"]
    assert main(["critical-speed", "--range", "1:1e4", "--hopf", "--format", "json"]) == 0
    crit = json.loads(capsys.readouterr().out)
    assert len(ref) == len(got) == 2 and len(crit["crossings"]) == 2
    for a, b, c in zip(ref, got, crit["crossings"]):
        assert a["hopf"]["criticality"] == b["hopf"]["criticality"] == c["hopf"]["criticality"]
        assert b["hopf"]["l1"] == pytest.approx(a["hopf"]["l1"], rel=1e-6)
        assert c["hopf"]["p0"] == pytest.approx(a["hopf"]["p0"], rel=1e-9)
    assert main(["crossings", "--along", "Omega=1:1e4:log", "--format", "json"]) == 0
    assert "hopf" not in json.loads(capsys.readouterr().out)["crossings"][0]  # unchanged without --hopf


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(4))
def test_random_regular_pad_models_against_the_ode_route(rising_friction_model, seed):
    """Random asymmetric parameter sets with rising friction: the implicit route equals the explicit ODE's."""
    rng = np.random.default_rng(seed)
    sets = [f"k_ip1={10 ** rng.uniform(5, 8):.6g}", f"k_ip2={10 ** rng.uniform(5, 8):.6g}",
            f"mu1={rng.uniform(0.3, 0.7):.4f}", f"mu2={rng.uniform(0.3, 0.7):.4f}",
            f"s={-(10 ** rng.uniform(-3, -2)):.4g}", f"d1={rng.uniform(1, 10):.3f}", f"k2={rng.uniform(4e6, 8e6):.4g}"]
    space = resolve_space(rising_friction_model, None, None, sets)
    every = hopf_points(space, Axis("Omega", 1.0, 1e4, log=True))
    pts = [hp for hp in every if hp.hopf is not None]
    assert pts and len(pts) == len(every), [hp.message for hp in every]  # a normal form at every crossing
    for hp in pts:
        ex = hp.hopf
        assert hp.simulated is None  # rate-dependent pads: the simulated equations keep the pads' rates
        ode = _ode_l1_along(space, "Omega", ex)
        tol = 10 * (ex.l1_error + ode.l1_error) + 1e-4 * abs(ode.l1)
        assert abs(ex.l1 - ode.l1) <= tol, (sets, ex.l1, ode.l1)
        assert ex.dlambda_dp == pytest.approx(ode.dlambda_dp, rel=1e-6)
        # a_j ~ |Re c1|^(-1/2): the amplitudes agree to half the relative tolerance of l1
        rtol = 0.5 * tol / abs(ode.l1) + 1e-5
        np.testing.assert_allclose(ex.amplitude_coefficients, ode.amplitude_coefficients, rtol=rtol)


@pytest.mark.slow
def test_limit_cycles_of_the_regularised_pads_follow_the_exact_prediction(rising_friction_model):
    """Third route: periodic orbits shot on the explicit ODE of a slightly rising friction law (the pads' rates
    regularised, s = 1e-4 s/m) have the amplitude the exact Coulomb normal form predicts, not the quasi-static one.

    k_ip = 1e6: the quasi-static pad's l1 is 50x smaller, so its predicted amplitude is about 7x larger.
    """
    hc = hopf_points(resolve_space(None, None, None, ["k_ip=1e6"]), Axis("Omega", 10.0, 200.0))[0]
    exact, quasi = hc.hopf, hc.simulated
    reg = resolve_space(rising_friction_model, None, None, ["k_ip1=1e6", "k_ip2=1e6", "s=-1e-4"])
    h = hopf_points(reg, Axis("Omega", 10.0, 200.0))[0].hopf
    assert h.p0 == pytest.approx(exact.p0, rel=2e-2)  # mu(v0) = mu + s Omega r shifts the onset slightly
    system = model_system(reg, "Omega")
    dp = 1e-3 * h.p0
    o = find_periodic_orbit(system, h.cycle_guess(h.p0 + dp), tol=1e-8)
    tilt = o.amplitude[:2]
    np.testing.assert_allclose(tilt / exact.amplitude(exact.p0 + dp)[:2], 1.0, atol=1e-2)
    assert np.all(quasi.amplitude(quasi.p0 + dp)[:2] > 3 * tilt)


@pytest.mark.slow
def test_branch_of_regularised_pads(rising_friction_model):
    """The documented how-to: `cycles` on the regularised model continues past the stiff orbits where a
    sampling run of the explicit integrator failed (it used to end the command), and its first points have
    the exact Coulomb normal form's amplitude."""
    from brakesqueal import squeal_branch

    exact = hopf_points(resolve_space(None, None, None, ["k_ip=1e6"]), Axis("Omega", 10.0, 200.0))[0].hopf
    reg = resolve_space(rising_friction_model, None, None, ["k_ip1=1e6", "k_ip2=1e6", "s=-1e-4"])
    b = squeal_branch(reg, Axis("Omega", 60.0, 120.0), max_points=12)
    ds = b.data
    p, tilt = ds["p"].values, ds["tilt_amplitude"].values
    assert p.size == 12 and p[-1] > 86.0 and ds["stable"].values.all()
    h = b.hopf.branch_start
    i = 1  # closest to onset
    pred = float(np.max(exact.amplitude(exact.p0 + (p[i] - h.p0))[:2]))
    assert tilt[i] == pytest.approx(pred, rel=2e-2)


def test_tilted_silent_motion_with_rigid_pads():
    """mu1 h10 != mu2 h20: a tilted silent motion; rigid pads are kept in the linearization (a singular
    descriptor E). Both routes describe the same equations: same onset and l1, no quasi-static note."""
    space = resolve_space(None, "paper-fig3", None, ["h10=0.0101", "k_ip=inf"])
    (hp,) = hopf_points(space, Axis("Omega", 20.0, 50.0))
    ex, sim = hp.hopf, hp.simulated
    assert ex is not None and sim is not None  # different states: (q, dq, l1, l2) and (q, dq)
    assert ex.state_names[-2:] == ("l1", "l2") and "quasi-static" not in hp.message
    assert ex.p0 == pytest.approx(sim.p0, rel=1e-7)
    assert abs(ex.l1 - sim.l1) <= 10 * (ex.l1_error + sim.l1_error) + 1e-5 * abs(sim.l1)
    np.testing.assert_allclose(ex.amplitude_coefficients[:4], sim.amplitude_coefficients, rtol=1e-3)


@pytest.mark.slow
def test_pad_slope_option_equals_the_model_file_route(rising_friction_model, capsys):
    """`squeal_branch(pad_slope=...)` / `cycles --pad-slope` build the same regularised model as the how-to's
    model file (an independent construction: TOML text vs. the spec rewritten in code)."""
    from brakesqueal.model.options import regularised_pads
    from brakesqueal import squeal_branch

    coulomb = resolve_space(None, None, None, ["k_ip=1e6"])
    toml = resolve_space(rising_friction_model, None, None, ["k_ip1=1e6", "k_ip2=1e6", "s=-1e-4"])
    a = squeal_branch(coulomb, Axis("Omega", 60.0, 120.0), max_points=5, pad_slope=1e-4)
    b = squeal_branch(toml, Axis("Omega", 60.0, 120.0), max_points=5)
    assert a.hopf.simulated is None and a.hopf.hopf.state_names[-2:] == ("l1", "l2")  # rates kept
    np.testing.assert_allclose(a.data["p"].values, b.data["p"].values, rtol=1e-7)
    np.testing.assert_allclose(a.data["tilt_amplitude"].values[1:], b.data["tilt_amplitude"].values[1:], rtol=1e-4)
    assert regularised_pads(ParameterSpace.from_preset("six-dof"), 1e-4).resolve({}).model.name == "six-dof"
    for bad in ("0", "-1e-4", "0.5", "nan"):
        assert main(["cycles", "--set", "k_ip=1e6", "--along", "Omega=60:120", "--pad-slope", bad]) == 2
        assert "--pad-slope" in capsys.readouterr().err


@pytest.mark.slow
def test_simulate_with_regularised_pads(capsys):
    """`simulate --pad-slope`: the pads' deformations become integrator states (their rates are kept)."""
    assert main(["simulate", "--set", "k_ip=1e6", "--set", "Omega=90", "--t-end", "0.005", "--pad-slope", "1e-4",
                 "--format", "json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["model"] == "paper+rising-pads" and d["t_end_reached"] == pytest.approx(0.005, abs=1 / 44100)
    assert main(["simulate", "--set", "k_ip=1e6", "--t-end", "0.005", "--pad-slope", "1"]) == 2
    assert "--pad-slope" in capsys.readouterr().err


def test_predictions_stay_in_the_parameter_range():
    """Along k_ip (Fig. 2's A and B) a leading-order extrapolation can leave k_ip > 0: it is not reported."""
    space = ParameterSpace.from_preset("paper-fig2", {"mu": 0.5})
    pts = hopf_points(space, Axis("k_ip", 1e5, 1e10, log=True))
    assert len(pts) == 2 and all(hp.hopf is not None for hp in pts)
    for hp in pts:
        for v in (hp.contact_loss, hp.sliding_reversal):
            assert v is None or v > 0
        if hp.sliding_reversal is not None:  # on the side where the cycles exist
            assert (hp.sliding_reversal - hp.hopf.p0) * hp.hopf.side > 0
    assert pts[0].contact_loss is None  # the extrapolation gave k_ip < 0 here
