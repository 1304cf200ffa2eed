"""Pads' rate coefficients at tilted silent motions: resolved, and the verdicts they imply right.

Without normal dampers, a massless pad's rate coefficient ``G_Ldot`` at a
tilted silent motion is a difference of terms that cancel to ``O(q^2)``
(about 1e-24 of them).  Evaluated in double precision it was rounding noise
of either sign or exactly 0: ``linearize`` reported pad modes of ``+1.4e22``
(unstable) where the motion is stable, maps marked stable cells unstable,
and ``crossings`` found 68 spurious crossings.

Reference (independent of the toolkit's numerics): the generated residuals
evaluated in mpmath at 50 and 80 digits, the silent motion refined by
Newton's method at that precision, every pad kept as a state, and the
eigenvalues of the pencil by shift-invert; only eigenvalues that agree at
both precisions are kept (:func:`reference_eigenvalues`).  The Jacobian used
there is checked against central differences of the residuals at 60 digits
(:func:`test_accurate_jacobian_matches_high_precision_differences`).
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

from brakesqueal import linearize, resolve_space
from brakesqueal.analysis.equilibrium import parameter_vector
from brakesqueal.analysis.linear import accurate_jacobian
from brakesqueal import Axis, stability_map
from brakesqueal.analysis.points import linear_verdict
from brakesqueal.analysis.robust import STABLE, UNDECIDED, UNSTABLE
from brakesqueal.codegen import compile_model

NO_DAMPERS = ["d1=0", "d2=0", "mu1=0.1", "mu2=0.1", "d_t=20"]


def _namespace(cm):
    ns = dict(sin=mpmath.sin, cos=mpmath.cos, tan=mpmath.tan, sqrt=mpmath.sqrt, exp=mpmath.exp, log=mpmath.log,
              abs=abs, pi=mpmath.pi)
    exec(cm.source, ns)
    return ns


def _hp_pencil(cm, ns, x0, pv, dps):
    """Silent motion refined at ``dps`` digits and the pencil ``(E, A)`` with every pad kept."""
    n, m, nx = cm.n, cm.m, cm.nx
    with mpmath.workdps(dps):
        p = [mpmath.mpf(float(v)) for v in pv]
        x = [mpmath.mpf(float(v)) for v in x0]
        unk = list(range(n)) + list(range(3 * n, 3 * n + m))
        for _ in range(60):
            r = mpmath.matrix(list(ns["residuals"](x, p)))
            Jf = list(ns["jacobians"](x, p))
            J = mpmath.matrix([[Jf[i * nx + j] for j in unk] for i in range(n + m)])
            dx = mpmath.lu_solve(J, -r)
            for k, j in enumerate(unk):
                x[j] += dx[k]
            if max(abs(v) for v in dx) < mpmath.mpf(10) ** (8 - dps) * (1 + max(abs(x[j]) for j in unk)):
                break
        Jf = list(ns["jacobians"](x, p))
        N = 2 * n + m
        E, A = mpmath.zeros(N, N), mpmath.zeros(N, N)
        for i in range(n):
            E[i, i], A[i, n + i] = 1, 1
        for i in range(n + m):
            for j in range(n):
                E[n + i, n + j] = Jf[i * nx + 2 * n + j]
                A[n + i, j] = -Jf[i * nx + j]
                A[n + i, n + j] = -Jf[i * nx + n + j]
            for j in range(m):
                E[n + i, 2 * n + j] = Jf[i * nx + 3 * n + m + j]
                A[n + i, 2 * n + j] = -Jf[i * nx + 3 * n + j]
        sig = mpmath.mpf("0.3719")
        mu = mpmath.eig(mpmath.inverse(A - sig * E) * E, left=False, right=False)
        big = max([abs(z) for z in mu] + [mpmath.mpf(1)])
        return [sig + 1 / z for z in mu if abs(z) > mpmath.mpf(10) ** (-(2 * dps) // 3) * big]


def reference_eigenvalues(params, x0):
    """Finite eigenvalues that agree at 50 and 80 digits (see the module docstring)."""
    cm = compile_model(params.model)
    ns = _namespace(cm)
    pv = parameter_vector(params)
    lo, hi = _hp_pencil(cm, ns, x0, pv, 50), _hp_pencil(cm, ns, x0, pv, 80)
    out = [complex(z) for z in hi if min(abs(z - w) for w in lo) <= 1e-12 * abs(z) + 1e-20]
    return np.array(sorted(out, key=lambda z: (-z.real, -z.imag)))


def _verdict_of(lam, rel=1e-9):
    top = lam[np.argmax(lam.real)]
    if top.real > rel * abs(top):
        return UNSTABLE
    if top.real < -rel * abs(top):
        return STABLE
    return UNDECIDED


def test_accurate_jacobian_matches_high_precision_differences():
    """Every entry of the pads' rate columns equals a 60-digit central difference of the residuals."""
    params = resolve_space("paper", None, None, [*NO_DAMPERS, "h10=0.011"]).resolve({})
    cm = compile_model(params.model)
    lm = linearize(params)
    x, pv = lm.silent.state(), parameter_vector(params)
    J = accurate_jacobian(cm, x, pv)
    ns = _namespace(cm)
    n, m, nx = cm.n, cm.m, cm.nx
    with mpmath.workdps(60):
        xm = [mpmath.mpf(float(v)) for v in x]
        pm = [mpmath.mpf(float(v)) for v in pv]
        h = mpmath.mpf(10) ** -25
        for c in range(3 * n + m, nx):
            up, dn = list(xm), list(xm)
            up[c] += h
            dn[c] -= h
            fd = [(a - b) / (2 * h) for a, b in zip(ns["residuals"](up, pm), ns["residuals"](dn, pm))]
            for r in range(n + m):
                assert abs(J[r, c] - float(fd[r])) <= 1e-12 * abs(float(fd[r])) + 1e-300
    # the pads' own rate coefficients are the tiny O(q^2) values, positive here (dissipative), not noise
    G_dL = J[n:, 3 * n + m:]
    assert np.all(np.diag(G_dL) > 0) and np.all(np.diag(G_dL) < 1e-20)


@pytest.mark.parametrize("model, sets", [
    ("paper", [*NO_DAMPERS, "h10=0.011"]),
    ("in-plane-pad", ["Theta=0.01", "Omega=2", "k=3e4", "h20=0.00999"]),
    ("in-plane-pad", ["h10=0.0105", "mu=0.06"]),
    ("paper", ["k_ip1=inf", "mu2=0.9"]),  # a rigid pad: an algebraic row of E (LinAlgError in `eigen` before)
])
def test_tilted_points_listed_eigenvalues_and_verdict_match_the_reference(model, sets):
    params = resolve_space(model, None, None, sets).resolve({})
    lm = linearize(params)
    assert not lm.silent.trivial
    ref = reference_eigenvalues(params, lm.silent.state())
    lam = lm.eigenvalues
    assert lam.size == ref.size
    for z in ref:
        assert np.min(np.abs(lam - z)) <= 1e-7 * abs(z)
    code, max_real, _ = linear_verdict(lm)
    assert code == _verdict_of(ref)
    assert max_real == pytest.approx(ref.real.max(), rel=1e-7)
    assert np.all(np.isfinite(lm.A))  # the state matrix exists (the algebraic pad eliminated)


def test_random_tilted_points_against_the_reference():
    """Random tilted points of both models without normal dampers: no verdict contradicts the reference."""
    rng = np.random.default_rng(20261127)
    decided = 0
    for i in range(10):
        if i % 2:
            model = "in-plane-pad"
            sets = [f"h10={0.01 + rng.uniform(-5e-4, 5e-4)!r}", f"mu={rng.uniform(0.05, 0.6)!r}",
                    f"Omega={10 ** rng.uniform(0, 2.5)!r}", f"k={10 ** rng.uniform(4, 7)!r}"]
        else:
            model = "paper"
            sets = ["d1=0", "d2=0", f"h10={0.01 + rng.uniform(1e-5, 2e-3)!r}", f"d_t={rng.uniform(0, 40)!r}",
                    f"mu1={rng.uniform(0.05, 0.5)!r}", f"mu2={rng.uniform(0.05, 0.5)!r}"]
        params = resolve_space(model, None, None, sets).resolve({})
        lm = linearize(params)
        if lm.silent.trivial:
            continue
        code, _, _ = linear_verdict(lm)
        ref = _verdict_of(reference_eigenvalues(params, lm.silent.state()))
        if code != UNDECIDED:
            decided += 1
            assert code == ref, (model, sets)
    assert decided >= 6


def test_map_cells_at_tilted_points_without_dampers_match_the_per_point_verdict():
    """The batched map route hands such points to the accurate per-point route (21 of 40 cells were wrong)."""
    space = resolve_space("paper", None, None, NO_DAMPERS)
    m = stability_map(space, Axis("h10", 0.0101, 0.012, 6), Axis("k_t", 1e7, 3e7, 3))
    ds = m.data
    for h in ds["h10"].values:
        for k in ds["k_t"].values:
            cell = ds.sel(h10=h, k_t=k)
            lm = linearize(space.resolve({"h10": float(h), "k_t": float(k)}))
            code, _, _ = linear_verdict(lm)
            assert code != UNDECIDED
            assert int(cell["status"]) == 1 and bool(cell["stable"]) == (code == STABLE)
    # the batched route keeps tilted points with normal dampers (their rate coefficients are resolved)
    fig3 = stability_map(resolve_space(None, "paper-fig3", None, ["h10=0.012"]),
                         Axis("mu1", 0.1, 0.8, 4), Axis("mu2", 0.1, 0.8, 4))
    assert np.all(fig3.data["status"].values == 1)
