"""Stability kernels, maps, crossings and critical speeds against independent computations.

References: eigenvalues of the numerically linearized model (``linearize``,
exact Jacobians of the compiled residuals, not the closed forms), NumPy
eigenvalues of the state matrix, and bisection on eigenvalues.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from brakesqueal import critical_speeds, crossings
from brakesqueal.analysis.crossings import critical_speeds_batch
from brakesqueal.analysis.kernels import real_roots
from brakesqueal import linearize
from brakesqueal import Axis, stability_map
from brakesqueal.analysis.equilibrium import parameter_vector
from brakesqueal.model import ParameterSpace
from brakesqueal.errors import ParameterError
from brakesqueal.codegen import build

FIG2 = ParameterSpace.from_preset("paper-fig2")


def eig_max_real(space, **values):
    return linearize(space.resolve(values)).max_real


def test_real_roots_against_numpy():
    rng = np.random.default_rng(3)
    for _ in range(50):
        r = np.sort(rng.uniform(-3, 3, 5))
        c = np.polynomial.polynomial.polyfromroots(r) * rng.uniform(0.5, 2)
        got = real_roots(c, -10, 10)
        np.testing.assert_allclose(got, r, rtol=1e-8, atol=1e-8)
    assert real_roots(np.array([1.0, 0.0, 1.0]), -5, 5).size == 0  # x^2 + 1


@pytest.mark.slow
def test_map_kernel_matches_eigenvalues_on_random_points():
    kern = build(FIG2.model).map_kernel(FIG2, "k_ip", "mu")
    assert kern is not None
    rng = np.random.default_rng(0)
    kip = 10 ** rng.uniform(5, 10, 120)
    mu = rng.uniform(0.05, 1.0, 120)
    outer = mu if kern.outer == "mu" else kip
    inner = kip if kern.inner == "k_ip" else mu
    for i in range(120):
        code = kern.verdicts(np.array([outer[i]]), np.array([inner[i]]))[0, 0]
        expected = eig_max_real(FIG2, mu=float(mu[i]), k_ip=float(kip[i])) < 0
        assert code == (1 if expected else 0)  # certified: never 2 (uncertain) away from the boundary


@pytest.mark.slow
def test_points_just_off_the_boundary():
    """Place points at relative distance 1e-7 on both sides of boundary points found by eigen bisection."""
    for mu in (0.3, 0.5, 0.8):
        space = ParameterSpace.from_preset("paper-fig2", {"mu": mu})
        f = lambda k: eig_max_real(space, k_ip=k)  # noqa: E731
        grid = np.logspace(5, 10, 60)
        vals = [f(k) for k in grid]
        roots = [brentq(f, a, b, rtol=1e-14) for a, b, fa, fb in zip(grid, grid[1:], vals, vals[1:]) if fa * fb < 0]
        assert roots
        kern = build(space.model).map_kernel(space, "k_ip", "mu")
        for k0 in roots:
            ks = np.array([k0 * (1 - 1e-7), k0 * (1 + 1e-7)])
            m = stability_map(space, Axis("k_ip", ks[0], ks[1], 2, True), Axis("mu", mu, mu * (1 + 1e-12), 2))
            got = m.data["stable"].sel(mu=mu, method="nearest").values
            expected = [f(k) < 0 for k in ks]
            assert list(got) == expected and expected[0] != expected[1]
        assert kern is not None


def test_map_dataset_consistent_with_linearize():
    m = stability_map(FIG2, Axis("k_ip", 1e5, 1e10, 9, True), Axis("mu", 0.1, 1.0, 7))
    ds = m.to_xarray()
    assert set(ds.data_vars) >= {"max_real", "stable", "frequency", "status"}
    assert set(ds["stable"].dims) == {"k_ip", "mu"}
    for kv in ds["k_ip"].values[::3]:
        for mv in ds["mu"].values[::3]:
            lm = linearize(FIG2.resolve({"k_ip": float(kv), "mu": float(mv)}))
            pt = ds.sel(k_ip=kv, mu=mv)
            assert bool(pt["stable"]) == (lm.max_real < 0)
            np.testing.assert_allclose(float(pt["max_real"]), lm.max_real, atol=1e-6 * np.abs(lm.eigenvalues).max())
            top = lm.eigenvalues[np.argmax(lm.eigenvalues.real)]
            np.testing.assert_allclose(float(pt["frequency"]), abs(top.imag) / (2 * np.pi), rtol=1e-6)


@pytest.mark.slow
def test_nontrivial_silent_motion_and_invalid_points_are_flagged():
    space = ParameterSpace.from_parameters(FIG2.resolve({}))
    m = stability_map(space, Axis("mu1", 0.3, 0.7, 3), Axis("k_t", 1e3, 1.88e7, 3, True), eigen=True)
    ds = m.data
    st = ds["status"].values
    assert (st == 1).any() and (st == 0).any()  # mu1 != mu2: non-trivial silent motion
    for mu1 in ds["mu1"].values:
        for kt in ds["k_t"].values:
            code = int(ds["status"].sel(mu1=mu1, k_t=kt))
            if code >= 2:
                assert not bool(ds["stable"].sel(mu1=mu1, k_t=kt))
            elif code == 1:
                lm = linearize(space.resolve({"mu1": float(mu1), "k_t": float(kt)}))
                assert not lm.silent.trivial
                assert bool(ds["stable"].sel(mu1=mu1, k_t=kt)) == (lm.max_real < 0)
    m2 = stability_map(FIG2, Axis("mu", -0.5, 0.5, 3), Axis("k_ip", 1e6, 1e7, 2, True))
    assert (m2.data["status"].sel(mu=-0.5).values == 4).all()
    assert not m2.data["stable"].sel(mu=-0.5).values.any()


def test_crossings_against_eigen_bisection():
    space = ParameterSpace.from_preset("paper-fig2", {"mu": 0.6})
    r = crossings(space, Axis("k_ip", 1e5, 1e10, 2, True))
    assert len(r.crossings) == 2
    f = lambda k: eig_max_real(space, k_ip=k)  # noqa: E731
    for v, d in r.crossings:
        ref = brentq(f, v * 0.99, v * 1.01, rtol=1e-15)
        assert abs(v / ref - 1) < 1e-9
        assert (d == "destabilizing") == (f(v * 1.001) > 0)
    assert r.stable_at_start == (f(1.0001e5) < 0)


def test_crossings_numeric_fallback_nontrivial():
    """Non-trivial silent motion, rigid tangential supports: the numeric route finds the onset of squeal."""
    base = ParameterSpace.from_preset("paper-fig3", {"k_ip": "inf"}).resolve({})
    sp2 = ParameterSpace.from_parameters(base.replace(h10=0.009))  # breaks eq. 49: non-trivial silent motion
    r = crossings(sp2, Axis("Omega", 10, 100, 2, True))
    assert "numeric" in r.method and not r.exhaustive and r.crossings
    f = lambda W: linearize(sp2.resolve({"Omega": W})).max_real  # noqa: E731
    for v, d in r.crossings:
        assert abs(f(v)) < 1e-6 * 1e4
        assert (f(v * 1.001) > 0) == (d == "destabilizing") and (f(v * 0.999) > 0) != (d == "destabilizing")


def _mp_descriptor_max_real(lm, dps=60):
    """Largest real part of the finite eigenvalues of E xi' = A xi (E regular), in mpmath from the floats."""
    import mpmath

    E, A = lm.descriptor
    with mpmath.workdps(dps):
        S = mpmath.inverse(mpmath.matrix(E.tolist())) * mpmath.matrix(A.tolist())
        ev = mpmath.eig(S, left=False, right=False)
        top = max(ev, key=lambda z: z.real)
        return float(top.real), float(top.imag)


def test_tilted_silent_motion_has_an_unstable_pad_mode():
    """At a tilted silent motion the massless pads keep their tangential rate (normal dampers couple in).

    Each pad's balance gets a rate term ``G_dL ~ c_ip mu d q2``; its own mode
    ``lambda ~ -G_L / G_dL`` is real and of order ``1/(c_ip mu d q2)``, positive
    for one of the two pads: the silent motion is unstable at every Omega.
    This is a genuine eigenvalue of the linearized model (checked here in
    60-digit arithmetic from the descriptor matrices) and must be in
    ``max_real``; the numeric route therefore reports no crossing (earlier
    versions dropped the pad blocks and found one at Omega ~ 35.23 rad/s).
    """
    base = ParameterSpace.from_preset("paper-fig3", {"k_ip": 1e8}).resolve({})
    sp2 = ParameterSpace.from_parameters(base.replace(h10=0.009))
    r = crossings(sp2, Axis("Omega", 10, 100, 2, True))
    assert "numeric" in r.method and not r.exhaustive and r.crossings == () and not r.stable_at_start
    for W in (10.0, 35.2, 100.0):
        lm = linearize(sp2.resolve({"Omega": W}))
        assert lm.pad_states == ("l1", "l2") and not lm.silent.trivial
        mr, mi = _mp_descriptor_max_real(lm)
        assert mr > 0 and abs(mi) < 1e-30 * mr  # real
        pad = [-lm.G_L[j, j] / lm.G_dL[j, j] for j in range(2)]
        assert max(pad) > 0 > min(pad)
        assert abs(mr / max(pad) - 1) < 1e-2  # the pad's own mode, slightly shifted by the coupling
        m = stability_map(sp2, Axis("Omega", W, W * 1.01, 2, True), Axis("k1", 6e6, 6.1e6, 2)).data
        assert not m["stable"].values.any() and np.all(m["status"].values == 1)
        np.testing.assert_allclose(m["max_real"].values, mr, rtol=1e-3)


@pytest.mark.parametrize("kip", [1e7, 1e8, math.inf])
@pytest.mark.parametrize("mu1", [0.5, 0.65])
def test_critical_speed_against_eigen_bisection(kip, mu1):
    space = ParameterSpace.from_preset("paper-fig3", {"mu1": mu1, "mu2": 1 - mu1, "k_ip": kip})
    r = critical_speeds(space, 1.0, 1e5)
    assert r.crossings and r.crossings[0][1] == "destabilizing"
    f = lambda W: eig_max_real(space, Omega=W)  # noqa: E731
    for v, d in r.crossings:
        ref = brentq(f, v * 0.999, v * 1.001, rtol=1e-15, xtol=1e-300)
        assert abs(v / ref - 1) <= 1e-10
        assert (f(v * 1.0001) > 0) == (d == "destabilizing")
    assert r.Omega_crit == r.crossings[0][0]


def test_critical_speed_batch_equals_single_and_fallback():
    mus = [0.5, 0.6, 0.7]
    spaces = [ParameterSpace.from_preset("paper-fig3", {"mu1": m, "mu2": 1 - m}) for m in mus]
    P = np.array([parameter_vector(s.resolve({})) for s in spaces])
    roots, dirs, counts, start = critical_speeds_batch(build('paper'), P, 1.0, 1e5)
    for i, s in enumerate(spaces):
        numeric = crossings(s, Axis("Omega", 1.0, 1e5, 2, True))  # independent: sympy polynomial path
        assert counts[i] == len(numeric.crossings)
        for k, (v, _) in enumerate(numeric.crossings):
            assert abs(roots[i, k] / v - 1) < 1e-10


@pytest.mark.parametrize("bad", [
    lambda: Axis("k_ip", 2.0, 1.0), lambda: Axis("k_ip", 1.0, 1.0), lambda: Axis("k_ip", -1.0, 1.0, 3, True),
    lambda: Axis("k_ip", 1.0, 2.0, 1), lambda: stability_map(FIG2, Axis("N0", 1, 2), Axis("mu", 0.1, 1)),
    lambda: stability_map(FIG2, Axis("nope", 1, 2), Axis("mu", 0.1, 1)),
    lambda: stability_map(FIG2, Axis("mu", 0.1, 1, 40000), Axis("k_ip", 1, 2, 40000)),
])
def test_bad_input(bad):
    with pytest.raises(ParameterError):
        bad()
