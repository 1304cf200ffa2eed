"""Stiff flows: the implicit methods of ``ScipyFlow`` with the Jacobian of the augmented (variational) system,
the flow choice of ``squeal_branch`` and a unilateral branch of stiffly damped pads.

Independent routes: the augmented Jacobian against central differences of the augmented right-hand side;
Radau's flow, end state and monodromy against DOP853's (two integrators of different families); the first
lift-off of a unilateral damped-pad branch (shooting with the piecewise flow through events) against the
contact loss of harmonic balance on the same model (Fourier series of the smooth equations, no time stepping).
"""

from __future__ import annotations

import numpy as np
import pytest

from brakesqueal import Axis
from brakesqueal.errors import ParameterError
from brakesqueal.model.options import damped_pads, resolve_space
from brakesqueal.nonlinear import PiecewiseSystem, ScipyFlow, SmoothSystem, Transition
from brakesqueal.nonlinear.flow import _augmented_rhs, augmented_jacobian
from brakesqueal.nonlinear.squeal import _shooting_flow, stiffness_ratio
from brakesqueal import model_piecewise_system, squeal_branch

LAM = 2e3  # rate of the fast variable: stiff against the O(1) oscillation


def _f(x, p, c=0.0):
    return np.array([x[1], p * (1 - x[0] ** 2) * x[1] - x[0] + (x[2] - x[0]) - c * max(x[0] - 1.0, 0.0),
                     -LAM * (x[2] - np.sin(x[0]))])


def _jac(x, p, c=0.0):
    return np.array([[0.0, 1.0, 0.0],
                     [-2 * p * x[0] * x[1] - 2.0 - c * (x[0] > 1.0), p * (1 - x[0] ** 2), 1.0],
                     [LAM * np.cos(x[0]), 0.0, -LAM]])  # fmt: skip


def stiff_vdp() -> SmoothSystem:
    """Van der Pol with a fast variable ``z`` relaxing (rate ``LAM``) to ``sin x``: nonlinear A, stiff."""
    return SmoothSystem(_f, _jac, 3, dfdp=lambda x, p: np.array([0.0, (1 - x[0] ** 2) * x[1], 0.0]),
                        state_names=("x", "v", "z"), parameter_name="mu")  # fmt: skip


def stiff_vdp_stop(c: float = 5.0) -> PiecewiseSystem:
    """The same with a one-sided spring ``c (x - 1)`` beyond ``x = 1`` (mode 1: Jacobian by central differences)."""

    def fd_jac(x, p):  # fourth-order central differences, like a lifted pad's mode
        J = np.empty((3, 3))
        for j in range(3):
            e = np.zeros(3)
            e[j] = 1e-3
            J[:, j] = (8 * (_f(x + e, p, c) - _f(x - e, p, c)) - (_f(x + 2 * e, p, c) - _f(x - 2 * e, p, c))) / 12e-3
        return J

    free = stiff_vdp()
    stop = SmoothSystem(lambda x, p: _f(x, p, c), fd_jac, 3, state_names=free.state_names, parameter_name="mu")
    h = lambda x, p: x[0] - 1.0  # noqa: E731
    return PiecewiseSystem((free, stop), ((Transition(h, 1, +1, name="stop"),), (Transition(h, 0, -1, name="free"),)),
                           lambda x, p: int(x[0] > 1.0))  # fmt: skip


def _fd_augmented(system: SmoothSystem, y: np.ndarray, p: float) -> np.ndarray:
    rhs = _augmented_rhs(system, p, system.n)
    N = y.size
    J = np.empty((N, N))
    for j in range(N):
        h = 1e-6 * max(1.0, abs(y[j]))
        e = np.zeros(N)
        e[j] = h
        J[:, j] = (8 * (rhs(0, y + e) - rhs(0, y - e)) - (rhs(0, y + 2 * e) - rhs(0, y - 2 * e))) / (12 * h)
    return J


@pytest.mark.parametrize("which", ["smooth", "piecewise-free", "piecewise-stop"])
def test_the_augmented_jacobian_equals_central_differences_of_the_augmented_rhs(which):
    rng = np.random.default_rng(7)
    system = {"smooth": stiff_vdp(), "piecewise-free": stiff_vdp_stop().modes[0],
              "piecewise-stop": stiff_vdp_stop().modes[1]}[which]
    n = system.n
    for _ in range(3):
        x = rng.uniform(-2, 2, n)
        if which == "piecewise-stop":
            x[0] = 1.5  # inside the stop's region, away from its kink
        y = np.concatenate([x, rng.normal(size=n * (n + 1))])
        p = float(rng.uniform(0.5, 2.0))
        ref = _fd_augmented(system, y, p)
        full = augmented_jacobian(system, y, p, coupling=True)
        block = augmented_jacobian(system, y, p, coupling=False)
        scale = np.max(np.abs(ref))
        assert np.max(np.abs(full - ref)) < 1e-7 * scale
        # the block form is the same without the coupling dA/dx Z (which is not zero here: the test can fail)
        coupling = ref[n:, :n]
        assert np.max(np.abs(coupling)) > 1e-2 * scale
        assert np.max(np.abs(block[n:, :n])) == 0.0
        assert np.max(np.abs(block[:n] - ref[:n])) < 1e-7 * scale
        assert np.max(np.abs(block[n:, n:] - ref[n:, n:])) < 1e-7 * scale
    with pytest.raises(ParameterError, match="n \\(n \\+ 2\\)"):
        augmented_jacobian(system, np.zeros(n), 1.0)


def _orbit_start(system):
    """A point near the stiff Van der Pol's limit cycle (mu = 1) and its period, from the Hopf-free guess."""
    fl = ScipyFlow(system, rtol=1e-10)
    x = fl(np.array([2.0, 0.0, np.sin(2.0)]), 20.0, 1.0, sensitivities=False).x  # settle onto the cycle
    return x


@pytest.mark.slow
@pytest.mark.parametrize("jacobian", ["block", "full"])
@pytest.mark.parametrize("method", ["Radau", "BDF"])
def test_implicit_flows_agree_with_dop853_end_state_and_monodromy(method, jacobian):
    """Stiffness ratio LAM / omega ~ 2000; the implicit flow with the (block or full) augmented Jacobian gives the
    same end state and monodromy as DOP853 (measured: Radau 1e-11, BDF 1e-8 of the scale at rtol 1e-10)."""
    system = stiff_vdp()
    x0 = _orbit_start(system)
    scale = np.array([2.0, 2.0, 1.0])
    ref = ScipyFlow(system, rtol=1e-12)(x0, 6.5, 1.0, scale=scale)
    fl = ScipyFlow(system, method=method, rtol=1e-10, augmented_jacobian=jacobian)
    assert fl.implicit
    r = fl(x0, 6.5, 1.0, scale=scale)
    tol = 1e-8 if method == "Radau" else 1e-6
    assert np.max(np.abs(r.x - ref.x) / scale) < tol
    assert np.max(np.abs(r.monodromy - ref.monodromy)) < tol * np.max(np.abs(ref.monodromy))
    assert np.max(np.abs(r.dp - ref.dp)) < tol * np.max(np.abs(ref.dp))
    assert r.nfev < ref.nfev  # the explicit method pays for the stiffness


@pytest.mark.slow
def test_radau_through_events_agrees_with_dop853():
    system = stiff_vdp_stop()
    x0 = _orbit_start(system.modes[0])
    scale = np.array([2.0, 2.0, 1.0])
    ref = ScipyFlow(system, rtol=1e-12)(x0, 6.5, 1.0, scale=scale)
    r = ScipyFlow(system, method="Radau", rtol=1e-10)(x0, 6.5, 1.0, scale=scale)
    assert [e.name for e in r.events] == [e.name for e in ref.events] and len(ref.events) >= 2
    assert max(abs(a.t - b.t) for a, b in zip(r.events, ref.events)) < 1e-8
    assert np.max(np.abs(r.x - ref.x) / scale) < 1e-8
    assert np.max(np.abs(r.monodromy - ref.monodromy)) < 1e-7 * np.max(np.abs(ref.monodromy))


def test_flow_options_are_validated():
    system = stiff_vdp()
    with pytest.raises(ParameterError, match="'method'"):
        ScipyFlow(system, method="Euler")
    with pytest.raises(ParameterError, match="'augmented_jacobian'"):
        ScipyFlow(system, method="Radau", augmented_jacobian="exact")  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match="'atol_monodromy'"):
        ScipyFlow(system, atol_monodromy=0.0)
    with pytest.raises(ParameterError, match="'omega'"):
        stiffness_ratio(system, np.zeros(3), 1.0, 0.0)


def test_the_flow_choice_follows_the_stiffness():
    """Damped pads (rate k_ip / d_ip = 1e6 1/s against the Hopf frequency 1.1e4 rad/s): stiff, the monodromy's
    tolerance is relaxed to rtol; rigid pads: not stiff, ScipyFlow's defaults (documented numbers unchanged)."""
    stiff = damped_pads(resolve_space(preset="paper-fig3", sets=["mu1=0.5", "mu2=0.5", "k_ip=1e6"]), 1.0)
    rigid = resolve_space(preset="paper-fig3", sets=["mu1=0.5", "mu2=0.5", "k_ip=inf"])
    out = {}
    for key, space in (("stiff", stiff), ("rigid", rigid)):
        pw = model_piecewise_system(space, "Omega")
        x0 = pw.simulation_model.silent(space.resolve({"Omega": 100.0})).y
        A = pw.modes[0].jacobian(x0, 100.0)
        w, _ = np.linalg.eig(A)
        omega = float(np.max(np.abs(w.imag[np.abs(w.real) < 10.0])))  # the flutter pair, the Hopf frequency's order

        class H:  # the parts of a HopfResult the choice reads
            pass

        h = H()
        h.x0, h.p0, h.omega0 = x0, 100.0, omega
        out[key] = _shooting_flow(pw, h, None)
        with pytest.raises(ParameterError, match="'flow_method'"):
            _shooting_flow(pw, h, "Euler")
        flow, info = _shooting_flow(pw, h, "Radau")
        assert flow.method == "Radau" and flow.implicit and info["flow_choice"] == "given"
    flow, info = out["stiff"]
    assert info["stiffness_ratio"] > 50 and flow.method == "DOP853" and flow.atol_monodromy == flow.rtol
    flow, info = out["rigid"]
    assert info["stiffness_ratio"] < 2 and flow.method == "DOP853" and flow.atol_monodromy is None
    assert info["flow_choice"] == "automatic"
    with pytest.raises(ParameterError, match="'flow_method'"):
        squeal_branch(rigid, Axis("Omega", 30.0, 40.0), flow_method="RK4")


@pytest.mark.slow
def test_a_stiffly_damped_unilateral_branch_lifts_off_where_harmonic_balance_loses_contact():
    """d_ip = 3 N s/m (pad modes at -3.3e5 1/s, stiffness ratio 30: the relaxed monodromy tolerance): the unilateral
    shooting branch's first lift-off (the GR point, located with the piecewise flow, and the contact loss) equals
    harmonic balance's contact loss on the same model to 1e-7 relative.  Reference: 128.0278174 rad/s by
    ``harmonic_branch(damped_pads(space, 3), Axis("Omega", 30, 200))`` (exact pads, docs/nonlinear.md, damper
    section); measured 2026-11-28 here: GR 128.0278175, contact loss 128.0278176 (the whole branch to 200 rad/s
    in 95 s against 5.5 min before)."""
    space = damped_pads(resolve_space(preset="paper-fig3", sets=["mu1=0.5", "mu2=0.5", "k_ip=1e6"]), 3.0)
    # ds_max=0.1 (default 0.05): the points between the onset and the lift-off only carry the continuation there;
    # the GR point and the contact loss are located between the bracketing points by the Illinois method and do
    # not depend on the steps (squeal_branch, Notes: to about 1e-8; measured 2026-11-29: GR 128.0278196 with
    # the default steps, 128.0278213 with these, both within 3.1e-8 of harmonic balance's).  With it the branch
    # reaches the end of the range (20 points) and costs 17 % less (104 s CPU against 125 s, same machine).
    br = squeal_branch(space, Axis("Omega", 30.0, 131.0), max_points=30, contact="unilateral", ds_max=0.1)
    ds = br.data
    assert ds.attrs["flow_method"] == "DOP853" and ds.attrs["stiffness_ratio"] > 20
    assert ds.attrs["flow_atol_monodromy"] == ds.attrs["flow_rtol"]
    gr = [float(v) for k, v in zip(ds["special_kind"].values, ds["special_p"].values) if str(k) == "GR"]
    assert gr, list(ds["special_kind"].values)
    hb_loss = 128.0278174
    assert br.contact_loss is not None
    assert abs(br.contact_loss - hb_loss) < 1e-7 * hb_loss, br.contact_loss
    assert abs(gr[0] - hb_loss) < 1e-7 * hb_loss, gr[0]
    # past lift-off both pads are lifted for part of the period; the branch stays stable (docs)
    last = int(np.argmax(ds["p"].values))
    assert ds["p"].values[last] > gr[0] + 0.3 and np.all(ds["duty_cycle"].values[last] < 0.99)
    assert bool(ds["stable"].values[last])
    errs = [o.trivial_multiplier_error for o in br.branch.orbits[1:]]
    assert max(errs) < 1e-7, errs
