"""The globalised silent-motion solver on dense soft-support maps, against an independent solver.

Issue: Newton's method alone reported "no silent motion" at isolated points of
soft-support maps where one exists.  Here every point of a dense map at soft
supports must have a silent motion that (a) satisfies the *independent*
Newton-Euler equations of ``tests/reference/newton_euler.py`` (sympy.physics
vectors, mpmath evaluation; no package code) and (b) at random points equals
the root an independent solver written here finds: scipy's ``hybr`` on the
reference residuals, continued in the preload ``N0`` from zero (where the
silent motion is q = 0), a different path from the package's continuation in
the asymmetry.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import root

from brakesqueal import silent_motion
from brakesqueal.analysis.equilibrium import parameter_vector
from brakesqueal.model import Parameters, get_model
from brakesqueal.symbolic.model import PARAMETER_SYMBOLS, STATE_SYMBOLS

ref = pytest.importorskip("tests.reference.newton_euler")

#: the parameter set of the issue (a silent motion near q0 = (-1.1e-8, 3.84e-4) rad that Newton missed)
ISSUE = dict(Theta=0.2, Phi=0.38, k_t=2e4, d_t=0.3, k1=5e6, k2=7e6, d1=4.0, d2=8.0, k_ip1=3e7, k_ip2=8e7, mu1=0.25,
             mu2=0.3, h10=0.026745762711864407, h20=0.012, r=0.12, N0=2500.0, Omega=60.0)  # fmt: skip


def _params(**over: float) -> Parameters:
    return Parameters(get_model("paper"), {**ISSUE, **over})


def _ref(p: Parameters) -> dict[str, float]:
    return dict(zip(PARAMETER_SYMBOLS, parameter_vector(p)))


def _reference_silent_motion(pr: dict[str, float]) -> np.ndarray:
    """(q1, q2, l1, l2) by hybr on the reference equations, natural continuation in N0 from 0 (adaptive steps)."""
    names = ("q1", "q2", "l1", "l2")

    def fun(y: np.ndarray, q: dict[str, float]) -> np.ndarray:
        s = dict.fromkeys(ref.STATE, 0.0)
        s.update(zip(names, map(float, y)))
        psi, g = ref.residuals(s, q)
        return np.concatenate([np.asarray(psi) / pr["k_t"], g])

    x, s, ds = np.zeros(4), 0.0, 0.05
    while s < 1.0:
        assert ds > 1e-6, f"the independent continuation stalled at N0 = {s * pr['N0']:g} N"
        s1 = min(1.0, s + ds)
        sol = root(fun, x, args=(dict(pr, N0=s1 * pr["N0"]),), method="hybr", options={"xtol": 1e-14})
        if sol.success and np.max(np.abs(sol.x[:2] - x[:2])) < 0.02:
            x, s, ds = sol.x, s1, min(2 * ds, 0.25)
        else:
            ds /= 2
    return x


@pytest.mark.slow
def test_the_issue_instance_and_its_neighbour_have_the_same_silent_motion():
    a = silent_motion(_params())
    b = silent_motion(_params(mu1=0.25 + 1e-9))
    want = _reference_silent_motion(_ref(_params()))
    assert abs(a.q_m0[1] - want[1]) <= 1e-8 * abs(want[1])
    assert abs(a.q_m0[1] - 3.84e-4) < 0.01e-4  # the value quoted in the issue
    assert np.linalg.norm(a.q_m0 - b.q_m0) <= 1e-6 * np.linalg.norm(a.q_m0)


@pytest.mark.parametrize("k_t", [2e3, 2e4])
def test_dense_soft_support_map_has_no_false_failures(k_t):
    """Every point of a 24 x 24 (mu1, h10) map: found, and a root of the independent equations."""
    rng = np.random.default_rng(int(k_t))
    base = _params(k_t=k_t)
    grid = [(m, h) for m in np.linspace(0.05, 1.0, 24) for h in np.linspace(0.002, 0.05, 24)]
    found = {}
    for mu1, h10 in grid:
        found[(mu1, h10)] = silent_motion(base.replace(mu1=mu1, h10=h10))  # raises (fails the test) on a miss
    for i in rng.choice(len(grid), 40, replace=False):  # independent residuals at a random subset
        mu1, h10 = grid[i]
        p, sm = base.replace(mu1=mu1, h10=h10), found[grid[i]]
        psi, g = ref.residuals(dict(zip(STATE_SYMBOLS, sm.state())), _ref(p))
        assert np.max(np.abs(psi)) <= 1e-9 * p.k_t * max(np.abs(sm.q_m0).max(), 1e-9), (mu1, h10)
        assert np.max(np.abs(g)) <= 1e-12, (mu1, h10)
    for i in rng.choice(len(grid), 4, replace=False):  # the same root as an independent solver's
        mu1, h10 = grid[i]
        want = _reference_silent_motion(_ref(base.replace(mu1=mu1, h10=h10)))
        got = found[grid[i]].q_m0
        assert np.linalg.norm(got - want[:2]) <= 1e-7 * np.linalg.norm(want[:2]) + 1e-15, (mu1, h10, got, want)
