"""The compiled exact Jacobian of the brake models (``SimulationModel.variational_kernels``).

Independent checks, at random states of the paper's model and of built models:
* ``nl_f`` equals the simulation's right-hand side (the integrator's ``rhs``);
* ``nl_jac`` equals central differences of that right-hand side (to the differences' error) and the
  Python route :func:`~brakesqueal.simulation.state_jacobian` (to ``1e-10`` relative);
* ``nl_dfdp`` equals central differences of the right-hand side in the parameter.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from brakesqueal.model import ParameterSpace
from brakesqueal.model.components import Disk, FrictionLaw, ModelSpec, Pad
from brakesqueal.model.library import paper_parameters_full
from brakesqueal.model.parameters import Parameters
from brakesqueal import simulation_model

CASES = [
    ("paper-fig3", {"mu1": 0.5, "mu2": 0.5, "k_ip": math.inf}, "Omega"),
    ("paper-fig3", {"mu1": 0.5, "mu2": 0.5, "k_ip": 1e8}, "Omega"),
    ("minimal", {}, None),
    ("six-dof", {}, None),
]


def _states(st, rng, k=3):
    scale = np.maximum(np.abs(st.y), 1e-3)
    return scale, [st.y + 1e-3 * rng.standard_normal(st.y.size) * scale for _ in range(k)]


def _check_jacobian(params, what):
    sim = simulation_model(params.model)
    st = sim.silent(params)
    f, jac = sim.vector_field(params, st)
    mod = sim.variational_kernels()
    th = sim.variational_theta(params, silent=st)
    ny = st.y.size
    rng = np.random.default_rng(7)
    scale, ys = _states(st, rng)
    for y in [st.y, *ys]:
        out = np.empty(ny)
        mod.nl_f(y, 0.0, th, out)
        np.testing.assert_allclose(out, f(y), rtol=1e-12, atol=1e-12 * np.max(np.abs(out)))
        Jc = np.empty((ny, ny))
        mod.nl_jac(y, 0.0, th, Jc)
        Jp = jac(y)
        big = np.max(np.abs(Jp))
        assert np.max(np.abs(Jc - Jp)) <= 1e-10 * big, (what, np.max(np.abs(Jc - Jp)) / big)
        cols = []
        for i in range(ny):
            e = np.zeros(ny)
            e[i] = 1e-6 * scale[i]
            cols.append((8 * (f(y + e) - f(y - e)) - (f(y + 2 * e) - f(y - 2 * e))) / (12 * e[i]))
        fd = np.column_stack(cols)
        assert np.max(np.abs(Jc - fd)) <= 1e-7 * big, (what, np.max(np.abs(Jc - fd)) / big)
        wrong = Jc.copy()
        wrong[ny - 1, 0] += 1e-5 * big  # negative control: the comparison sees an error of this size
        assert np.max(np.abs(wrong - fd)) > 1e-7 * big
    return sim


@pytest.mark.slow
@pytest.mark.parametrize("preset, overrides, _name", CASES)
def test_compiled_jacobian_is_exact(preset, overrides, _name):
    _check_jacobian(ParameterSpace.from_preset(preset, overrides).resolve({}), preset)


@pytest.mark.slow
def test_compiled_jacobian_with_a_dynamic_pad():
    """A coulomb pad (quasi-static) and a falling-friction pad (its deformation a state) at a tilted silent motion."""
    pads = tuple(Pad(n, face, radius="r", k=f"k{n}", d=f"d{n}", preload="N0", k_ip=f"k_ip{n}",
                     friction=FrictionLaw(law, f"mu{n}", slope="s2" if law == "linear" else None))
                 for n, face, law in (("1", "upper", "coulomb"), ("2", "lower", "linear")))  # fmt: skip
    par = {**paper_parameters_full(), "k_ip1": 1e4, "k_ip2": 1e4, "s2": 0.05}
    params = Parameters(ModelSpec("mixed-pads-variational", Disk(), pads, parameters=par), {**par, "h10": 0.012})
    sim = _check_jacobian(params, "mixed pads")
    assert sim.pad_kinds == ("quasi-static", "dynamic") and len(sim.state_names) == 5


@pytest.mark.parametrize("preset, overrides, name", [c for c in CASES if c[2]])
def test_compiled_parameter_derivative(preset, overrides, name):
    space = ParameterSpace.from_preset(preset, overrides)
    params = space.resolve({})
    p0 = float(params[name]) if hasattr(params, "__getitem__") else float(getattr(params, name))
    sim = simulation_model(params.model)
    st = sim.silent(params)
    h = 1e-2 * abs(p0)  # fourth-order differences: truncation ~h^4, rounding ~eps |f| / h
    vec = [sim.parameter_vector(space.resolve({name: p0 + k * h})) for k in (-1, 1)]
    dp = (vec[1] - vec[0]) / (2 * h)
    mod = sim.variational_kernels()
    th = sim.variational_theta(params, dp, silent=st)
    rng = np.random.default_rng(3)
    _scale, ys = _states(st, rng)
    for y in ys:
        out = np.empty(y.size)
        mod.nl_dfdp(y, 0.0, th, out)
        fs = [sim.vector_field(space.resolve({name: p0 + k * h}), st)[0](y) for k in (-2, -1, 1, 2)]
        fd = (8 * (fs[2] - fs[1]) - (fs[3] - fs[0])) / (12 * h)
        noise = 100 * np.finfo(float).eps * max(np.max(np.abs(f)) for f in fs) / h
        assert np.max(np.abs(out - fd)) <= 1e-7 * np.max(np.abs(fd)) + noise, np.max(np.abs(out - fd))
        assert np.max(np.abs(fd)) > 1e3 * noise  # the check is not vacuous


def test_branch_with_compiled_jacobian_equals_python_route():
    """The limit-cycle branch of the paper's model: compiled flow (generated Jacobian) vs ScipyFlow (Python)."""
    from brakesqueal import Axis
    from brakesqueal.nonlinear import ScipyFlow, continue_cycles
    from brakesqueal import model_flow
    from brakesqueal import hopf_points, model_system

    space = ParameterSpace.from_preset("paper-fig3", {"mu1": 0.5, "mu2": 0.5, "k_ip": math.inf})
    hp = hopf_points(space, Axis("Omega", 30.0, 40.0))[0]
    system = model_system(space, "Omega")
    kw = {"max_points": 8, "tol": 1e-8, "ds_max": 0.02}
    new = continue_cycles(system, hp.hopf, (30.0, 40.0), flow=model_flow(space, "Omega", system=system), **kw).data
    old = continue_cycles(system, hp.hopf, (30.0, 40.0), flow=ScipyFlow(system), **kw).data
    assert new.sizes["point"] == old.sizes["point"] == 8
    assert new.attrs["integrator"].startswith("CompiledFlow") and old.attrs["integrator"].startswith("ScipyFlow")
    for key in ("p", "period", "amplitude", "floquet_re", "floquet_im", "floquet_abs"):
        a, b = old[key].values, new[key].values
        np.testing.assert_allclose(b, a, rtol=1e-7, atol=1e-7 * np.nanmax(np.abs(a)), err_msg=key)
    assert np.all(new["trivial_multiplier_error"].values[1:] < 1e-8)
    assert new["p"].values[-1] > new["p"].values[1]  # the branch moved
