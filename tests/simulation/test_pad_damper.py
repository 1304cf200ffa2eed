"""A tangential damper ``d_ip`` beside a massless pad's spring (not in the paper): the pads' true rates through lift-off.

A massless pad whose tangential rate is a state cannot reach lift-off without it
(``test_unilateral_dynamic_pads.py``: ``dG/dldot`` shrinks with ``F_n`` and folds first).  With the damper the
pad's balance ``k_ip (l - u_m) + d_ip (ldot - u_mdot) + f_t + mu* N0 = 0`` has ``dG/dldot >= d_ip / k_ip > 0`` at
every normal force, and a lifted pad (``f_t = 0``) relaxes to its unloaded spring with the time constant
``d_ip / k_ip``.  The checks, each against something written here:

* the model files: a damper needs a finite ``k_ip`` (reader and schema agree, ``test_model_schema.py``);
  ``damped_pads`` names its option and range;
* the generated balance differs from the undamped one by exactly ``c_ip d_ip ldot`` (SymPy);
* the linearization's pad modes lie at ``-k_ip / d_ip`` (the first-order mode of a spring-damper, to the
  friction geometry's small correction) and the disk's eigenvalues tend to the paper's pads' as ``d_ip -> 0``;
* the unilateral simulation passes lift-off and re-contact, and a lifted pad's deformation follows the
  exponential relaxation ``l(t) = l_r + (l(t_0) - l_r) exp(-(t - t_0) k_ip / d_ip)``, ``l_r = -mu N0 / k_ip``
  (the unloaded spring, ``l`` measured from the silent motion), to the integrator's tolerance.
"""

from __future__ import annotations

import copy
import math
import tomllib
from typing import Any

import numpy as np
import pytest
import sympy as sp

from brakesqueal.errors import ParameterError
from brakesqueal.model.components import Pad
from brakesqueal.model.io import model_to_toml, spec_from_dict
from brakesqueal.model.library import get_model
from brakesqueal.model.options import MAX_PAD_DAMPING, damped_pads, resolve_space
from brakesqueal import simulate, simulation_model
from brakesqueal.symbolic.assemble import build_equations

SETS = ["mu1=0.5", "mu2=0.5", "k_ip=1e6"]


def _damped_model_file(tmp_path: Any) -> str:
    """The paper's model with ``d_ip = "d_ip"`` on both pads (a free parameter of preset paper-fig3) as a TOML file."""
    doc = tomllib.loads(model_to_toml(get_model("paper")))
    doc["name"] = "paper-damped"
    for pad in doc["pads"]:
        pad["d_ip"] = "d_ip"
    doc["parameters"]["d_ip"] = 10.0
    doc["presets"] = {"paper-fig3": copy.deepcopy(doc["presets"]["paper-fig3"])}
    doc["presets"]["paper-fig3"]["free"]["d_ip"] = 10.0
    path = tmp_path / "paper-damped.toml"
    path.write_text(model_to_toml(spec_from_dict(doc, source="test")))
    return str(path)


@pytest.fixture(scope="module")
def damped_space(tmp_path_factory: Any) -> Any:
    return resolve_space(_damped_model_file(tmp_path_factory.mktemp("damped")), "paper-fig3", None, SETS)


def test_a_damper_needs_a_finite_tangential_spring() -> None:
    Pad("1", "upper", k="k", d="d", k_ip="k_ip", d_ip=1.0).validate()
    Pad("1", "upper", k="k", d="d", k_ip="k_ip", d_ip="d_ip").validate()
    with pytest.raises(ParameterError, match=r"pad '1'.*d_ip needs a finite tangential stiffness k_ip"):
        Pad("1", "upper", k="k", d="d", d_ip=1.0).validate()


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, math.inf, 2 * MAX_PAD_DAMPING, "x"])
def test_damped_pads_names_its_option_and_range(bad: Any) -> None:
    space = resolve_space(preset="paper-fig3", sets=SETS)
    with pytest.raises(ParameterError, match=r"'pad_damping' must be in \(0, 1e\+06\] N s/m"):
        damped_pads(space, bad)


def test_damped_pads_changes_only_massless_pads_with_a_finite_spring() -> None:
    space = resolve_space(preset="paper-fig3", sets=SETS)
    damped = damped_pads(space, 3.0)
    spec = damped.resolve({}).model
    # one parameter for every pad, fixed at the value given and settable: one compiled model for every damping
    assert [p.d_ip for p in spec.pads] == ["d_ip", "d_ip"] and spec.name.endswith("+damped-pads")
    assert damped.resolve({})["d_ip"] == 3.0 and damped.resolve({"d_ip": 0.5})["d_ip"] == 0.5
    assert simulation_model(spec).pad_kinds == ("dynamic", "dynamic")
    rigid = resolve_space(preset="minimal-model")  # k_ip = inf: nothing to damp
    assert damped_pads(rigid, 3.0) is rigid
    six = resolve_space(model="six-dof")  # the pads have their own tangential DOF and damper
    assert damped_pads(six, 3.0) is six


def test_the_balance_gains_exactly_the_damper_force() -> None:
    """G(d_ip) - G(0) = c_ip d_ip ldot: the damper force d_ip ldot divided by the spring's stiffness."""
    spec = get_model("paper")
    from dataclasses import replace

    damped = replace(spec, pads=tuple(replace(p, d_ip=7.0) for p in spec.pads))
    e0, e1 = build_equations(spec, "sympy"), build_equations(damped, "sympy")
    assert e1.L == e0.L and e1.dL == e0.dL
    for j, name in enumerate(("c_ip1", "c_ip2")):
        diff = sp.simplify(sp.sympify(e1.G[j]) - sp.sympify(e0.G[j]) - sp.Symbol(name) * 7 * e0.dL[j])
        assert diff == 0
    for i in range(e0.n):  # the disk's equations do not see the damper (it acts between pad and ground)
        assert sp.simplify(sp.sympify(e1.R[i]) - sp.sympify(e0.R[i])) == 0


def test_linear_pad_modes_and_the_limit_of_no_damper(damped_space: Any) -> None:
    params0 = resolve_space(preset="paper-fig3", sets=SETS).resolve({"Omega": 120.0})
    A0, _ = simulation_model(params0.model).linear_matrix(params0)
    lead0 = np.linalg.eigvals(A0)
    lead0 = lead0[np.argmax(lead0.real)]
    sim = simulation_model(damped_space.resolve({}).model)
    gaps = []
    for d in (100.0, 10.0, 1.0, 0.1):
        params = damped_space.resolve({"Omega": 120.0, "d_ip": d})
        A, _ = sim.linear_matrix(params)
        assert A.shape == (6, 6)  # q1, q2, their rates and the two pads' deformations
        ev = np.linalg.eigvals(A)
        pad = ev[np.argsort(ev.real)[:2]]  # the two fastest modes
        k = 1e6
        assert np.allclose(pad.imag, 0.0) and np.allclose(pad.real, -k / d, rtol=0.05), (d, pad)
        lead = ev[np.argmax(ev.real)]
        gaps.append(abs(lead - lead0) / abs(lead0))
    # the disk's leading eigenvalue tends to the undamped pads' (the paper's model) as d_ip -> 0
    assert all(b < a / 5 for a, b in zip(gaps, gaps[1:])), gaps
    assert gaps[-1] < 1e-6, gaps


def test_unilateral_simulation_passes_lift_off_and_a_lifted_pad_relaxes(damped_space: Any) -> None:
    d_ip, k_ip, mu, N0 = 10.0, 1e6, 0.5, 3000.0
    params = damped_space.resolve({"Omega": 160.0, "d_ip": d_ip})
    sim = simulation_model(params.model)
    st = sim.silent(params)
    v = np.real(sim.linear_modes(params).right[:, 0])
    x0 = st.y + 5e-3 * v / np.abs(v[:2]).max()  # a tilt of 5 mrad along the leading mode: near the limit cycle
    tr = simulate(params, 4e-3, x0=x0, contact="unilateral", events="continue", rtol=1e-10, atol=1e-13,
                  sample_rate=4e6)
    assert tr.status == "finished", tr.message
    assert tr.engaged is not None and not tr.engaged.all() and tr.engaged.any(axis=0).all()
    names = set(tr.event_times)
    assert {"contact-loss-pad-1", "re-contact-pad-1"} <= names, names
    tau, l_r = d_ip / k_ip, -mu * N0 / k_ip
    checked = 0
    for j in range(2):
        lifted = ~tr.engaged[:, j]
        starts = np.flatnonzero(lifted[1:] & ~lifted[:-1]) + 1
        for s in starts:
            end = s
            while end + 1 < lifted.size and lifted[end + 1]:
                end += 1
            if end - s < 20:
                continue
            t, l = tr.t[s:end + 1], tr.l[s:end + 1, j]
            expected = l_r + (l[0] - l_r) * np.exp(-(t - t[0]) / tau)
            assert np.abs(l - expected).max() < 1e-6 * abs(l[0] - l_r) + 1e-12, (j, s)
            checked += 1
    assert checked >= 2


def test_a_tilted_start_puts_the_damped_pads_at_rest_on_their_supports(damped_space: Any) -> None:
    """Given only the tilt, the damped pads start with ``ldot = 0``: G(Q0, 0, l0, 0) = 0 (the spring carries the
    friction), not at the silent motion's ``l`` (the damper would then carry the whole change of the friction force,
    ``ldot ~ 1e3 N / 10 N s/m``, faster than the sliding speed: a spurious reversal at the start)."""
    params = damped_space.resolve({"Omega": 160.0, "d_ip": 10.0})
    sim = simulation_model(params.model)
    tr = simulate(params, 2e-4, perturbation=[8e-3, 0.0], contact="unilateral")
    assert tr.status == "finished" and "damped pads at rest" in tr.start, (tr.status, tr.message)
    y0, p = tr.y[0], sim.parameter_vector(params)
    l = np.array(y0[4:6])
    g = np.empty(5)
    sim.kernels.pad_balance(np.ascontiguousarray(y0), l, np.zeros(2), p, g)
    assert np.abs(g[:2]).max() < 1e-14 and np.abs(l - sim.silent(params).l).min() > 1e-5  # moved, and balanced
    # the pad states given (the silent motion's l): kept, and the start is the spurious reversal described above
    with pytest.raises(ParameterError, match="does not slide forward at the initial state"):
        simulate(params, 2e-4, x0=sim.silent(params).y + np.r_[8e-3, 0, 0, 0, 0, 0], contact="unilateral")


def test_the_command_line_option(capsys: Any) -> None:
    from brakesqueal.cli import main

    assert main(["cycles", "--set", "k_ip=1e6", "--along", "Omega=60:120", "--pad-damping", "0"]) == 2
    assert "'--pad-damping' must be in (0, 1e+06] N s/m" in capsys.readouterr().err  # the option's name
    assert main(["simulate", "--preset", "paper-fig3", "--set", "k_ip=1e6", "--set", "mu1=0.5", "--set", "mu2=0.5",
                 "--set", "Omega=160", "--pad-damping", "10", "--q0", "5e-3,0", "--contact", "unilateral",
                 "--events", "continue", "--t-end", "0.004", "--format", "json"]) == 0
    import json

    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "finished" and out["model"] == "paper+damped-pads"
    assert all(0.5 < v < 0.99 for v in out["duty_cycle"].values())  # both pads lift off and come back


def test_hopf_with_a_damper_is_the_damped_models(capsys: Any) -> None:
    """`hopf --pad-damping D` analyses the damped model: its first crossing is where the damped model's leading
    eigenvalue crosses (bracketed here by its linearization), not the undamped model's."""
    import json

    from brakesqueal.cli import main

    sets = ["--preset", "paper-fig3", "--set", "k_ip=1e6", "--set", "mu1=0.5", "--set", "mu2=0.5"]
    assert main(["hopf", *sets, "--along", "Omega=30:100", "--pad-damping", "10", "--format", "json"]) == 0
    h = json.loads(capsys.readouterr().out)["crossings"][0]["hopf"]
    assert main(["hopf", *sets, "--along", "Omega=30:100", "--format", "json"]) == 0
    h0 = json.loads(capsys.readouterr().out)["crossings"][0]["hopf"]
    assert abs(h["p0"] - h0["p0"]) > 0.5  # the damper of 10 N s/m moves the onset (63.84 against 64.81 rad/s)
    space = damped_pads(resolve_space(preset="paper-fig3", sets=SETS), 10.0)
    sim = simulation_model(space.resolve({}).model)
    lead = [np.linalg.eigvals(sim.linear_matrix(space.resolve({"Omega": w}))[0]).real.max()
            for w in (h["p0"] - 1e-3, h["p0"] + 1e-3)]
    assert lead[0] < 0 < lead[1], lead
    assert h["criticality"] == "supercritical"


def test_the_kernels_with_lifted_damped_pads_match_the_equations(damped_space: Any) -> None:
    """rhs_u (any combination of lifted pads) = the symbolic equations with those pads' engagement 0, evaluated
    independently: SymPy's lambdify of R and G, each pad's rate bracketed by SciPy's brentq (G_j is monotone in
    ldot_j with a damper), the accelerations from R's mass matrix and forcing (random states)."""
    from scipy.optimize import brentq

    params = damped_space.resolve({"Omega": 120.0, "d_ip": 10.0})
    spec = params.model
    sim = simulation_model(spec)
    k, st, p = sim.kernels, sim.silent(params), sim.parameter_vector(params)
    chi = sp.symbols("chi1 chi2")
    eq = build_equations(spec, "sympy", engagement={pad.name: c for pad, c in zip(spec.pads, chi)})
    args = [*eq.Q, *eq.dQ, *eq.ddQ, *eq.L, *eq.dL, *eq.params, *chi]
    R = sp.lambdify(args, list(eq.R), "numpy")
    G = sp.lambdify(args, list(eq.G), "numpy")
    rng = np.random.default_rng(7)
    for _ in range(4):
        y = st.y + np.concatenate([rng.uniform(-3e-3, 3e-3, 2), rng.uniform(-30, 30, 2), rng.uniform(-3e-4, 3e-4, 2)])
        for eng in ([1, 1], [0, 1], [1, 0], [0, 0]):
            out = np.empty(6)
            l, dl = st.l.copy(), st.dl.copy()
            k.rhs_u(y, l, dl, p, st.ztol, np.empty(5), np.empty(6), np.array(eng, dtype=np.int64), np.empty(5), out)

            def g(j: int, v: float, dls: list[float]) -> float:
                d = list(dls)
                d[j] = v
                return float(G(*y[:4], 0.0, 0.0, *y[4:6], *d, *p, *eng)[j])

            rates = [0.0, 0.0]
            for j in range(2):  # G_j depends on its own rate only
                rates[j] = brentq(lambda v, j=j: g(j, v, rates), -1e4, 1e4, xtol=1e-14, rtol=1e-14)
            f0 = np.array(R(*y[:4], 0.0, 0.0, *y[4:6], *rates, *p, *eng), dtype=float)
            M = np.column_stack([np.array(R(*y[:4], *e, *y[4:6], *rates, *p, *eng), dtype=float) - f0
                                 for e in ((1.0, 0.0), (0.0, 1.0))])
            want = np.concatenate([y[2:4], np.linalg.solve(M, -f0), rates])
            assert np.allclose(out, want, rtol=1e-8, atol=1e-9 * np.abs(want).max()), (eng, out, want)
        # a lifted pad relaxes: its rate is -(l - l_r) k_ip / d_ip, not the pressed pad's
        assert abs(out[4] - (-(y[4] + 0.5 * 3000.0 / 1e6) * 1e6 / 10.0)) < 1e-6 * abs(out[4])
