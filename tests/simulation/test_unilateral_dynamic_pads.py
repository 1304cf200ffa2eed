"""Unilateral contact with pads whose tangential deformation is a state (rate-dependent friction): refused, and why.

The pads of ``regularised_pads(space, slope)`` (friction ``mu + slope v``) keep their tangential rate
``ldot`` as the root of the friction balance ``G(Q, Qdot, l, ldot) = 0``.  ``ldot`` enters ``G`` through the
friction force ``F_n mu(v) t_p`` and through ``F_n`` itself (the support damper acts on ``hdot``, which
depends on ``ldot`` on a tilted disk), so ``dG/dldot`` shrinks with ``F_n``: at ``F_n = 0`` only the damper's
share is left.  On the paper-fig3 parameters (``mu = 0.5``, ``k_ip = 1e6``, slope ``1e-4``, ``Omega = 130``)
the tests below show, with the generated ``pad_balance`` and central differences of it (independent of its
generated derivative), that ``dG/dldot`` falls by more than two orders of magnitude while ``F_n`` falls from
the preload to about 100-115 N (integrated), and that the root ``ldot`` folds (``dG/dldot = 0``) while the pad
is still pressed (followed along a first-order extrapolation from the last state with ``F_n >= 200 N``):
the pad mode ``-G_l/G_ldot`` passes through infinity before lift-off.  The compiled integrator consequently fails
there (before any ``F_n`` reaches 0), which is why ``contact="unilateral"`` refuses these pads instead of
modelling a lift-off it cannot reach.  (Measured 2026-11-27: the fold at ``F_n`` about 97-105 N.)
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from brakesqueal.errors import ParameterError
from brakesqueal.model.options import regularised_pads, resolve_space
from brakesqueal import simulate, simulation_model

pytestmark = pytest.mark.slow  # module fixtures dominate: the whole module runs in `make test-slow`

SETS = ["mu1=0.5", "mu2=0.5", "k_ip1=1e6", "k_ip2=1e6"]


@pytest.fixture(scope="module")
def case():
    space = regularised_pads(resolve_space(preset="paper-fig3", sets=SETS), 1e-4)
    params = space.resolve({"Omega": 130.0})
    sim = simulation_model(params.model)
    assert sim.pad_kinds == ("dynamic", "dynamic")
    st = sim.silent(params)
    modes = sim.linear_modes(params)
    v = np.real(modes.right[:, 0])
    x0 = st.y + 5e-3 * v / np.abs(v[:2]).max()  # a tilt of 5 mrad along the leading mode: F_n swings by ~3 kN
    tr = simulate(params, 3e-4, x0=x0, contact="bilateral", events="off", sample_rate=1e8)
    return sim, params, st, x0, tr


def test_unilateral_contact_refuses_dynamic_pads_and_names_them(case):
    sim, params, st, x0, _tr = case
    with pytest.raises(ParameterError, match=r"needs a tangential damper d_ip > 0 .*\(l1, l2, rate-dependent friction\).*dG/dldot"):
        simulate(params, 1e-3, x0=x0, contact="unilateral", events="continue")


def _G(sim, p, y, l, dl, j):
    g = np.empty(2 * l.size + 1)
    sim.kernels.pad_balance(np.ascontiguousarray(y), l, dl, p, g)
    return g[j], g[l.size + j]


def _dG_fd(sim, p, y, l, dl, j):
    """Central difference of the generated G_j in ldot_j (step 1e-4 m/s; independent of the generated dG/dldot)."""
    e = 1e-4
    a, b = dl.copy(), dl.copy()
    a[j] += e
    b[j] -= e
    return (_G(sim, p, y, l, a, j)[0] - _G(sim, p, y, l, b, j)[0]) / (2 * e)


def test_the_pressed_pad_rate_balance_degenerates_before_lift_off(case):
    sim, params, st, _x0, tr = case
    p = sim.parameter_vector(params)
    # the pressed equations cannot be integrated to F_n = 0: the run fails while every pad is still pressed
    assert tr.status == "failed"
    assert "cannot reach contact loss when its rate balance degenerates first" in tr.message  # says why
    ok = np.isfinite(tr.contact[:, 0, 0])
    Fn = tr.contact[ok, :, 0]
    assert Fn.min() > 50.0  # N: no pad reached F_n = 0
    i = int(np.flatnonzero(ok)[-1])
    j = int(np.argmin(tr.contact[i, :, 0]))  # the pad approaching lift-off
    y, l, dl = tr.y[i], tr.l[i].copy(), tr.l_rates[i].copy()
    # generated derivative against central differences, at the start and at the last state
    for yy, ll, dd in ((tr.y[0], tr.l[0].copy(), tr.l_rates[0].copy()), (y, l, dl)):
        g, gd = _G(sim, p, yy, ll, dd, j)
        assert abs(g) < 1e-12
        assert gd == pytest.approx(_dG_fd(sim, p, yy, ll, dd, j), rel=1e-5)
    gd0, gd1 = _G(sim, p, tr.y[0], tr.l[0].copy(), tr.l_rates[0].copy(), j)[1], _G(sim, p, y, l, dl, j)[1]
    assert gd0 > 0 and gd1 > 0  # G_l = 1: the pad mode -1/G_ldot is stable so far ...
    assert gd1 < 0.01 * gd0  # ... but more than 100 times faster than at the start (F_n: ~3 kN -> ~115 N)
    # from the last integrated state with F_n >= 200 N (independent of how far the integrator gets), continue the
    # approach to lift-off to first order (state along its rate, l along ldot) and follow the root ldot of G_j:
    # before F_n reaches 0 its slope dG/dldot falls to 0 (the followed root meets another one and disappears: a
    # fold of the rate balance, where the pad mode -G_l/G_ldot passes through infinity)
    i = int(np.flatnonzero(ok & (tr.contact[:, j, 0] >= 200.0))[-1])
    y, l, dl = tr.y[i], tr.l[i].copy(), tr.l_rates[i].copy()
    f = np.empty(y.size)
    sim.kernels.rhs(np.ascontiguousarray(y), l.copy(), dl.copy(), p, st.ztol, np.empty(2 * l.size + 1),
                    np.empty(sim.n * sim.n + sim.n), f)
    cb = np.empty(7 * len(sim.pads))
    root, start, end_force = dl[j], None, None
    for dt in np.linspace(0.0, 6e-6, 121):
        ys, ls = y + f * dt, l + dl * dt

        def G(d, ys=ys, ls=ls):
            dd = dl.copy()
            dd[j] = d
            return _G(sim, p, ys, ls, dd, j)[0]

        dd = dl.copy()
        dd[j] = root
        sim.kernels.contact(np.ascontiguousarray(ys), ls, dd, p, cb)
        force = cb[7 * j]
        assert force > 0.0, "the followed root reached F_n = 0"
        grid = root + np.linspace(-1.0, 1.0, 201)
        vals = np.array([G(d) for d in grid])
        k = np.flatnonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))
        if not k.size:
            end_force = force  # the followed root has disappeared (fold)
            break
        k0 = k[np.argmin(np.abs(grid[k] - root))]
        root = brentq(G, grid[k0], grid[k0 + 1], xtol=1e-12)
        dd[j] = root
        slope = _dG_fd(sim, p, ys, ls, dd, j)
        start = slope if start is None else start
        if slope <= 0.0:
            end_force = force  # the slope has changed sign
            break
    assert start is not None and start > 0
    assert end_force is not None and end_force > 20.0  # N: the rate balance folds while the pad is still pressed
