"""No route may give a wrong stability verdict (issue 10, items 1, 5, 6).

Every route — map kernel, per-point route, sweep, exact crossings, critical
speeds, built-model maps — is compared with an INDEPENDENT reference:
``M, D, K`` of the Newton–Euler reference model (``tests/reference``,
``sympy.physics.mechanics``, evaluated in mpmath at 40 digits from the
parameters given by ``space.resolve``), and the eigenvalues of the state
matrix in mpmath.  Points whose true relative margin ``|max Re λ| / max |λ|``
is below ``1e-10`` are not asserted (a certified route may call them
undecided or give either verdict); a route may mark a point undecided
(status 5) only when that margin is below ``1e-8``.

Random cases (seeded NumPy): presets paper-fig2, paper-fig3, minimal-model
and a complete parameter set, extra ties (``k_ip2`` constant, ``N0 = c/mu``),
random axis pairs with random ranges (touching zero, negative where invalid,
log ranges spanning up to 120 decades).  No RuntimeWarning may be emitted.
"""

from __future__ import annotations

import functools
import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest

from brakesqueal import critical_speeds, crossings
from brakesqueal.analysis.crossings import critical_speeds_batch, exact_omega_crossings
from brakesqueal.analysis.equilibrium import parameter_vector
from brakesqueal import Axis, stability_map
from brakesqueal.analysis.maps import STATUS
from brakesqueal.analysis.robust import (
    STABLE, UNDECIDED, UNSTABLE, eigen_verdicts, isolate_real_roots, routh_exact,
    routh_verdicts,
)
from brakesqueal.errors import BrakesquealError
from brakesqueal.model import ParameterSpace
from brakesqueal.sweep.compute import build_space
from brakesqueal.codegen import build

pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")

SAFE = 1e-10  # relative margins below this are not asserted
UNDECIDED_OK = 1e-8  # status 5 only below this margin


# ---------------------------------------------------------------- independent reference
@functools.lru_cache(maxsize=1)
def _reference():
    import sympy as sp

    from tests.reference.newton_euler import trivial_linearization_symbolic

    M, D, K = trivial_linearization_symbolic()
    syms = sorted(M.free_symbols | D.free_symbols | K.free_symbols, key=str)
    f = sp.lambdify(syms, list(M) + list(D) + list(K), modules="mpmath")
    return f, [str(s) for s in syms]


def ref_margin(params) -> tuple[float, float]:
    """``(max Re λ, relative margin)`` of the trivial silent motion, reference model + mpmath eigenvalues."""
    f, names = _reference()
    d = dict(params.as_dict())
    d["c_ip1"] = 0.0 if math.isinf(d["k_ip1"]) else 1.0 / d["k_ip1"]
    d["c_ip2"] = 0.0 if math.isinf(d["k_ip2"]) else 1.0 / d["k_ip2"]
    with mpmath.workdps(40):
        e = f(*[mpmath.mpf(d[n]) for n in names])
        M = mpmath.matrix([[e[0], e[1]], [e[2], e[3]]])
        D = mpmath.matrix([[e[4], e[5]], [e[6], e[7]]])
        K = mpmath.matrix([[e[8], e[9]], [e[10], e[11]]])
        Mi = mpmath.inverse(M)
        B, C = -Mi * K, -Mi * D
        A = mpmath.zeros(4, 4)
        A[0, 2] = A[1, 3] = 1
        for i in range(2):
            for j in range(2):
                A[2 + i, j], A[2 + i, 2 + j] = B[i, j], C[i, j]
        ev = mpmath.eig(A, left=False, right=False)
        top = max(ev, key=lambda z: z.real)
        scale = max(abs(z) for z in ev)
        return float(top.real), float(top.real / scale)


def trivial_eq49(prm) -> bool:
    """The paper's condition for the trivial silent motion, ``mu1 h10 = mu2 h20`` (eq. 49), to 1e-12 relative."""
    a, b = prm.mu1 * prm.h10, prm.mu2 * prm.h20
    return abs(a - b) <= 1e-12 * max(abs(a), abs(b))


def reference_point(space, values):
    """``None`` (invalid), ``"nontrivial"``, or ``(max_real, rel)``."""
    try:
        prm = space.resolve(values)
    except BrakesquealError:
        return None
    if not trivial_eq49(prm):
        return "nontrivial"
    return ref_margin(prm)


def check_point(ref, status, stable, max_real=None, where=""):
    if ref is None:
        assert status == 4, f"{where}: invalid parameters must have status 4, got {status}"
        assert not stable
        return
    if ref == "nontrivial":
        return
    mr, rel = ref
    assert status != 4, f"{where}: valid point flagged invalid"
    if status == 5:
        assert abs(rel) < UNDECIDED_OK, f"{where}: undecided although the margin is {rel:.3g}"
        assert not stable
        return
    assert status in (0, 1), f"{where}: status {status}"
    if max_real is not None and np.isfinite(max_real):
        assert bool(stable) == (max_real < 0), f"{where}: stable={stable} contradicts max_real={max_real}"
    if abs(rel) > SAFE:
        assert bool(stable) == (mr < 0), f"{where}: stable={stable}, reference max Re λ = {mr:.6g} (rel {rel:.3g})"


# ---------------------------------------------------------------- random cases
SPACES = [
    ("paper-fig2", {}, {}),
    ("paper-fig2", {}, {"k_ip2": "3e7"}),
    ("paper-fig3", {}, {}),
    ("paper-fig3", {}, {"k_ip2": "8e7"}),
    ("paper-fig3", {}, {"N0": "1500/mu1"}),
    ("minimal-model", {}, {"N0": "2000/mu"}),
    ("minimal-model", {}, {}),
    ("parameters", {}, {}),
]
# axes that keep the silent motion trivial in each space
AXES = {
    "paper-fig2": ["mu", "k_ip", "Omega", "k_t", "d1", "h", "Theta", "r"],
    "paper-fig3": ["mu1", "mu2", "k_ip", "Omega", "N0", "k_t", "h", "R_disk"],
    "minimal-model": ["mu", "N0", "Omega", "k_t", "d2", "Theta"],
    "parameters": ["k_ip1", "k_ip2", "Omega", "N0", "k_t", "d_t", "k1", "d2", "Theta", "Phi"],
}


def make_space(preset, values, tied):
    if preset == "parameters":
        base = ParameterSpace.from_preset("paper-fig2").resolve({})
        return ParameterSpace.from_parameters(base), {k: ("inf" if math.isinf(v) else v)
                                                      for k, v in base.as_dict().items()}
    return build_space(preset, tuple(values.items()), tuple(tied.items())), None


def random_axis(rng, name, num):
    if name in ("mu", "mu1", "mu2"):
        lo, hi = [(0.0, 1.0), (0.05, 1.0), (-0.3, 0.9), (0.2, 0.8), (0.5, 3.0)][rng.integers(5)]
        return Axis(name, lo, hi, num)
    if name in ("d1", "d2", "d_t"):
        return Axis(name, 0.0, float(rng.choice([10.0, 200.0])), num)
    if name in ("h",):
        return Axis(name, float(rng.choice([0.0, 0.005])), 0.05, num)
    if name in ("r", "R_disk"):
        return Axis(name, 0.05, 0.3, num)
    if name in ("Theta", "Phi"):
        return Axis(name, 0.01, 1.0, num, True)
    if name == "Omega":
        a = float(rng.uniform(-3, 3))
        return Axis(name, 10 ** a, 10 ** (a + rng.uniform(1, 8)), num, True)
    # stiffness-like / preload: wide log ranges, sometimes linear from zero
    if rng.random() < 0.2:
        return Axis(name, 0.0, float(10 ** rng.uniform(6, 9)), num)
    a = float(rng.uniform(-40, 8))
    return Axis(name, 10 ** a, 10 ** (a + rng.uniform(1, 60)), num, True)


def cases(seed, n):
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        preset, values, tied = SPACES[rng.integers(len(SPACES))]
        space, _ = make_space(preset, values, tied)
        names = [n for n in AXES[preset] if n in space.settable() and n not in space.tied]
        i, j = rng.choice(len(names), 2, replace=False)
        out.append((preset, values, tied, random_axis(rng, names[i], 5), random_axis(rng, names[j], 4)))
    return out


@pytest.mark.slow
@pytest.mark.parametrize("preset,values,tied,x,y", cases(101, 16))
def test_map_and_sweep_verdicts_against_reference(preset, values, tied, x, y):
    from brakesqueal.sweep import sweep

    space, params = make_space(preset, values, tied)
    m = stability_map(space, x, y).data
    mv = stability_map(space, x, y, eigen=False).data
    study = {"axes": {y.name: {"values": [float(v) for v in y.values()]},
                      x.name: {"values": [float(v) for v in x.values()]}},
             "compute": {"quantities": ["stable", "max_real"]}}
    study.update({"parameters": params} if params else {"preset": preset, "tied": tied})
    ds = sweep(study)
    for yv in y.values():
        for xv in x.values():
            ref = reference_point(space, {x.name: float(xv), y.name: float(yv)})
            pt = m.sel({x.name: xv, y.name: yv})
            where = f"{preset}{tied} {x.name}={xv:.6g} {y.name}={yv:.6g}"
            check_point(ref, int(pt["status"]), bool(pt["stable"]), float(pt["max_real"]), "map " + where)
            pv = mv.sel({x.name: xv, y.name: yv})
            check_point(ref, int(pv["status"]), bool(pv["stable"]), None, "map(eigen=False) " + where)
            ps = ds.sel({x.name: xv, y.name: yv})
            check_point(ref, int(ps["status"]), bool(ps["stable"]), float(ps["max_real"]), "sweep " + where)


def _path_reference(space, name, lo, hi, log, n=60):
    grid = np.geomspace(lo, hi, n) if log else np.linspace(lo, hi, n)
    return grid, [reference_point(space, {name: float(v)}) for v in grid]


def _check_crossings(space, r, name, log):
    grid, refs = _path_reference(space, name, r.start, r.stop, log)
    values = [v for v, _ in r.crossings]
    assert values == sorted(values)
    for k in range(len(grid) - 1):
        ra, rb = refs[k], refs[k + 1]
        if not (isinstance(ra, tuple) and isinstance(rb, tuple)) or min(abs(ra[1]), abs(rb[1])) < SAFE:
            continue
        if (ra[0] < 0) != (rb[0] < 0):
            inside = [v for v in values if grid[k] <= v <= grid[k + 1]]
            und = [u for u in r.undecided_ranges if u[0] <= grid[k + 1] and u[1] >= grid[k]]
            assert len(inside) % 2 == 1 or und, f"{name}: a stability change in [{grid[k]:g}, {grid[k + 1]:g}] is missing"
    checked = 0
    for k, (v, d) in enumerate(r.crossings):
        gap = min([abs(v - w) for w, _ in r.crossings if w != v] + [abs(v - r.start), abs(r.stop - v)])
        for rel in (1e-5, 1e-4, 1e-3, 1e-2):
            eps = rel * abs(v) if (log or v != 0) else rel * (r.stop - r.start)
            if eps >= 0.5 * gap:
                break
            before = reference_point(space, {name: v - eps})
            after = reference_point(space, {name: v + eps})
            if isinstance(before, tuple) and isinstance(after, tuple) and min(abs(before[1]), abs(after[1])) > SAFE:
                assert (before[0] < 0) != (after[0] < 0), f"{name} = {v}: not a stability change"
                assert (d == "destabilizing") == (before[0] < 0), f"{name} = {v}: wrong direction {d}"
                checked += 1
                break
    assert checked >= min(1, len(r.crossings)), "no reported crossing could be checked"
    first = next((rf for rf in refs if isinstance(rf, tuple)), None)
    if isinstance(refs[0], tuple) and abs(refs[0][1]) > SAFE and not (values and values[0] < grid[1]):
        assert r.stable_at_start == (refs[0][0] < 0)
    return first


@pytest.mark.parametrize("preset,values,tied,x,y", cases(202, 6))
def test_exact_crossings_against_reference(preset, values, tied, x, y):
    space, _ = make_space(preset, values, tied)
    start = x.start
    if not isinstance(reference_point(space, {x.name: start}), tuple):
        # crossings requires valid parameters at the start of the path
        start = float(x.values()[1]) if x.num > 1 else start
        if not isinstance(reference_point(space, {x.name: start}), tuple):
            pytest.skip("no valid start on this random path")
    r = crossings(space, Axis(x.name, start, x.stop, 2, x.log))
    assert r.exhaustive and "exact" in r.method
    _check_crossings(space, r, x.name, x.log)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(5))
def test_critical_speeds_against_reference(seed):
    rng = np.random.default_rng(300 + seed)
    preset, values, tied = [SPACES[k] for k in (2, 3, 4, 6)][seed % 4]
    space, _ = make_space(preset, values, tied)
    lo = 10 ** rng.uniform(-4, 1)
    hi = lo * 10 ** rng.uniform(3, 60)
    r = critical_speeds(space, lo, hi)
    assert r.complete and r.Omega_crit_certain
    _check_crossings(space, r, "Omega", True)
    ref = critical_speeds(space, 1.0, 1e5)  # the same crossings inside the narrower range
    inside = [(v, d) for v, d in r.crossings if 1.0 < v < 1e5]
    assert [d for _, d in inside] == [d for _, d in ref.crossings if lo < _ < hi]
    for (a, _), (b, _) in zip(inside, [c for c in ref.crossings if lo < c[0] < hi]):
        assert math.isclose(a, b, rel_tol=1e-9)


def test_critical_speed_batch_kernel_equals_exact_isolation():
    rng = np.random.default_rng(7)
    base = ParameterSpace.from_preset("paper-fig3")
    P = []
    for _ in range(12):
        m1 = rng.uniform(0.05, 0.95)
        prm = base.resolve({"mu1": m1, "mu2": rng.uniform(0.05, 0.95), "k_ip": 10 ** rng.uniform(5, 10)})
        P.append(parameter_vector(prm))
    P = np.array(P)
    for lo, hi in [(1.0, 1e5), (1e-3, 1e9), (1e-30, 1e30)]:
        roots, dirs, counts, start, status = critical_speeds_batch(build('paper'), P, lo, hi, 16, return_status=True)
        for i in range(len(P)):
            st, found, und = exact_omega_crossings(build('paper'), P[i], lo, hi)
            assert not und and status[i] == 0
            assert counts[i] == len(found) and bool(start[i]) == st
            for k, (v, d) in enumerate(found):
                assert math.isclose(roots[i, k], v, rel_tol=1e-10)
                assert dirs[i, k] == (1 if d == "stabilizing" else -1)


@pytest.mark.parametrize("model,x,y", [
    ("paper-2dof", Axis("k_ip1", 1e3, 1e12, 6, True), Axis("k1", 0.0, 1e7, 5)),
    ("minimal", Axis("mu", 0.0, 1.0, 6), Axis("d", 0.0, 50.0, 4)),
    ("six-dof", Axis("k_c", 1e7, 1e11, 5, True), Axis("mu2", 0.3, 0.7, 3)),
    ("eight-dof", Axis("k_c", 1e8, 1e10, 4, True), Axis("k_cn", 1e6, 1e9, 3, True)),
])
@pytest.mark.slow
def test_built_model_maps_against_mpmath_eigenvalues(model, x, y):
    """Every built-in model: certified verdicts vs mpmath eigenvalues of the model's own M, D, K (40 digits)."""
    from brakesqueal import linearize
    from brakesqueal.model import resolve_space

    space = resolve_space(model)
    for eigen in (True, False):
        ds = stability_map(space, x, y, eigen=eigen).data
        assert ("max_real" in ds) == eigen
        for yv in y.values():
            for xv in x.values():
                pt = ds.sel({x.name: xv, y.name: yv})
                st, code = bool(pt["stable"]), int(pt["status"])
                try:
                    lm = linearize(space.resolve({x.name: float(xv), y.name: float(yv)}))
                except BrakesquealError:
                    assert code >= 2 and not st
                    continue
                assert not lm.pad_states  # these models keep no pad state at these points
                n = lm.M.shape[0]
                with mpmath.workdps(40):
                    A = mpmath.zeros(2 * n, 2 * n)
                    Mi = mpmath.inverse(mpmath.matrix(lm.M.tolist()))
                    Bk, Bd = -Mi * mpmath.matrix(lm.K.tolist()), -Mi * mpmath.matrix(lm.D.tolist())
                    for i in range(n):
                        A[i, n + i] = 1
                        for j in range(n):
                            A[n + i, j], A[n + i, n + j] = Bk[i, j], Bd[i, j]
                    ev = mpmath.eig(A, left=False, right=False)
                    mr = float(max(z.real for z in ev))
                    rel = mr / float(max(abs(z) for z in ev))
                where = f"{model} {x.name}={xv:g} {y.name}={yv:g} eigen={eigen}"
                if code == 5:
                    assert abs(rel) < 1e-6, where  # built models: norm-wise input bound 2^-42
                    continue
                assert code in (0, 1), where
                assert (code == 0) == lm.silent.trivial, where
                if eigen:
                    assert st == (float(pt["max_real"]) < 0), where
                if abs(rel) > SAFE:
                    assert st == (mr < 0), f"{where}: reference {mr}"


# ---------------------------------------------------------------- the three reported reproductions
def test_issue1_sweep_with_unequal_pads_has_no_wrong_verdicts():
    from brakesqueal.sweep import sweep

    study = {"preset": "paper-fig3", "tied": {"k_ip2": "8e7"},
             "axes": {"mu1": "0.1:1.0:30", "k_ip": "1e6:1e9:20:log"},
             "compute": {"quantities": ["stable", "max_real"]}}
    ds = sweep(study)
    st, mr, status = ds["stable"].values, ds["max_real"].values, ds["status"].values
    assert np.all(status == 0)
    assert np.array_equal(st, mr < 0)  # stable and max_real never contradict each other
    assert 0.2 < st.mean() < 0.6
    space = build_space("paper-fig3", (), (("k_ip2", "8e7"),))
    rng = np.random.default_rng(1)
    for i, j in zip(rng.integers(0, 30, 30), rng.integers(0, 20, 30)):
        ref = reference_point(space, {"mu1": float(ds["mu1"][i]), "k_ip": float(ds["k_ip"][j])})
        check_point(ref, int(status[i, j]), bool(st[i, j]), float(mr[i, j]), f"mu1[{i}], k_ip[{j}]")
    assert bool(st[0, 0])  # mu1 = 0.1, k_ip = 1e6 is stable (the report)


def test_issue5_axis_starting_at_zero():
    space = ParameterSpace.from_preset("paper-fig2")
    x = Axis("k_ip", 1e5, 1e10, 10, True)
    a = stability_map(space, x, Axis("mu", 0.0, 1.0, 10)).data
    b = stability_map(space, x, Axis("mu", 0.1, 1.0, 10)).data
    assert np.all(a["status"].values[0] == 4) and not a["stable"].values[0].any()  # mu = 0: N0 = 1800/0
    # verdicts never depend on where the axis starts: rows with the same mu agree
    np.testing.assert_array_equal(a["stable"].sel(mu=1.0).values, b["stable"].sel(mu=1.0).values)
    for mu in a["mu"].values:
        for k in x.values():
            pt = a.sel(mu=mu, k_ip=k)
            check_point(reference_point(space, {"mu": float(mu), "k_ip": float(k)}), int(pt["status"]),
                        bool(pt["stable"]), float(pt["max_real"]), f"mu={mu:g} k_ip={k:g}")
    assert 0.3 < a["stable"].values[1:].mean() < 0.5


@pytest.mark.slow
def test_issue6_exact_crossings_over_huge_ranges():
    space = ParameterSpace.from_preset("paper-fig2", {"mu": 0.5})
    narrow = crossings(space, Axis("k_ip", 1e5, 1e10, 2, True))
    assert [d for _, d in narrow.crossings] == ["stabilizing", "destabilizing"]
    # finite non-zero parameter values are valid from a magnitude of 1e-100 up to 1e100 (model.roles
    # MIN_MAGNITUDE, MAX_MAGNITUDE): the pieces beyond are undecided, at either end
    for lo, hi in [(1e-100, 1e100), (1e-300, 1e300), (1.0, 1e60)]:
        wide = crossings(space, Axis("k_ip", lo, hi, 2, True))
        assert wide.complete == (hi <= 1e100 and lo >= 1e-100)
        assert all((a >= narrow.crossings[-1][0] * (1 - 1e-12) and b == hi)
                   or (a == lo and b <= narrow.crossings[0][0]) for a, b in wide.undecided_ranges)
        assert any(a == lo for a, _ in wide.undecided_ranges) == (lo < 1e-100)
        assert [d for _, d in wide.crossings] == [d for _, d in narrow.crossings]
        for (a, _), (b, _) in zip(wide.crossings, narrow.crossings):
            assert math.isclose(a, b, rel_tol=1e-12)
    assert [round(v, -2) for v, _ in narrow.crossings] == [230900.0, 1866000.0]
    fig3 = ParameterSpace.from_preset("paper-fig3")
    ref = critical_speeds(fig3, 1.0, 1e5)
    for lo, hi in [(1e-50, 1e50), (1e-5, 1e20), (1e-300, 1e300)]:
        r = critical_speeds(fig3, lo, hi)
        # as for k_ip above: past the allowed magnitude (1e100) the range holds invalid sets, so it is not complete
        # there (critical-speed and crossings agree); the onset below it stays certain
        low_cut = lo < 1e-100  # below the smallest allowed magnitude: undecided up to the first piece
        assert r.Omega_crit is not None and r.complete == (hi <= 1e100 and not low_cut)
        assert math.isclose(r.Omega_crit, ref.Omega_crit, rel_tol=1e-10)
        assert r.Omega_crit_certain == (not low_cut)
        assert all((a > r.Omega_crit and b == hi) or (a == lo and b < r.Omega_crit) for a, b in r.undecided_ranges)
        assert bool(r.undecided_ranges) == (hi > 1e100 or low_cut)


def test_no_stable_throughout_claim_without_proof():
    from brakesqueal.results import CriticalSpeedResult

    r = CriticalSpeedResult("Omega", 1.0, 1e5, True, True, (), "test", undecided_ranges=((10.0, 20.0),))
    assert r.Omega_crit is None and not r.Omega_crit_certain and "UNKNOWN" in r.text()
    r2 = CriticalSpeedResult("Omega", 1.0, 1e5, True, True, (), "grid", exhaustive=False)
    assert not r2.Omega_crit_certain and "UNKNOWN" in r2.text()
    r3 = CriticalSpeedResult("Omega", 1.0, 1e5, True, True, (), "exact")
    assert r3.Omega_crit_certain and "none (no destabilizing" in r3.text()
    assert STATUS[5] == "undecided"


# ---------------------------------------------------------------- primitives
def _poly_from_roots(roots):
    """Exact ascending coefficients of Π (λ - r) for rational / complex-rational roots (given as pairs)."""
    c = [Fraction(1)]
    for r in roots:
        if isinstance(r, tuple):  # conjugate pair a ± bi: λ² - 2a λ + a² + b²
            a, b = r
            q = [a * a + b * b, -2 * a, Fraction(1)]
        else:
            q = [-r, Fraction(1)]
        new = [Fraction(0)] * (len(c) + len(q) - 1)
        for i, x in enumerate(c):
            for j, y in enumerate(q):
                new[i + j] += x * y
        c = new
    return c


def test_routh_certified_and_exact_against_roots():
    rng = np.random.default_rng(11)
    for _ in range(400):
        roots = []
        for _ in range(rng.integers(1, 6)):
            a = Fraction(int(rng.integers(-40, 41)), int(rng.integers(1, 9))) * Fraction(2) ** int(rng.integers(-30, 30))
            if rng.random() < 0.6:
                roots.append((a, Fraction(int(rng.integers(1, 100))) * Fraction(2) ** int(rng.integers(-30, 30))))
            else:
                roots.append(a)
        c = _poly_from_roots(roots)
        truth = all((r[0] if isinstance(r, tuple) else r) < 0 for r in roots)
        assert routh_exact(c) == (STABLE if truth else UNSTABLE) or any(
            (r[0] if isinstance(r, tuple) else r) == 0 for r in roots)
        scale = 2.0 ** int(rng.integers(-600, 600))
        f = np.array([float(x) * scale for x in c])
        if not np.all(np.isfinite(f)) or np.any((f == 0) & np.array([x != 0 for x in c])):
            continue
        r = np.abs(f) * 2.0 ** -53  # the rounding of the conversion
        v = routh_verdicts(f, r)[0]
        assert v == UNDECIDED or v == (STABLE if truth else UNSTABLE)


def test_exact_isolation_over_hundreds_of_decades():
    roots = [Fraction(1, 10 ** 80), Fraction(3, 10 ** 5), Fraction(5, 2), Fraction(7 * 10 ** 90)]
    c = _poly_from_roots(roots + [(Fraction(1), Fraction(1))])
    iv = isolate_real_roots([c], Fraction(1, 10 ** 100), Fraction(10 ** 100))
    assert len(iv) == 4
    for (a, b, owners), r in zip(iv, roots):
        assert a <= r <= b and owners == {0: 1} and b - a <= 1e-14 * r
    # a second polynomial sharing one root: disjoint intervals with both owners
    iv2 = isolate_real_roots([c, [-Fraction(5, 2), Fraction(1)]], 1, 10)
    assert len(iv2) == 1 and iv2[0][2] == {0: 1, 1: 1}


def isolate_real_roots_float(coeffs: np.ndarray, radii: np.ndarray | None, lo: float, hi: float,
                             max_roots: int = 64) -> np.ndarray | None:
    """Certified isolation (compiled Descartes bisection) of the real roots of an interval polynomial.

    Parameters
    ----------
    coeffs, radii : ndarray
        Ascending coefficients and their absolute error bounds.
    lo, hi : float
        Open interval searched (finite; choose a well-scaled variable: the
        coefficients times ``max(|lo|, |hi|)^k`` must stay finite).
    max_roots : int
        Capacity.

    Returns
    -------
    ndarray, shape (k, 3), or None
        Brackets ``[a, b]`` (columns 0, 1) with certified opposite signs at
        the ends and exactly one simple root inside (for every polynomial
        within the radii), ascending, and a floating-point estimate of the
        root inside the bracket (column 2); ``None`` if it cannot certify
        (clustered or multiple roots, a root at ``lo`` or ``hi``).
    """
    from brakesqueal.analysis._compiled import isolate_roots

    c = np.ascontiguousarray(coeffs, dtype=float)
    r = np.zeros_like(c) if radii is None else np.ascontiguousarray(radii, dtype=float)
    d = c.size - 1
    out = np.empty((max_roots, 3))
    w = np.empty(d + 1)
    rw = np.empty(d + 1)
    stack = np.empty((512, 2))
    n = isolate_roots(c, r, d, float(lo), float(hi), out, w, rw, stack)
    return None if n < 0 else out[:n].copy()


def test_float_isolation_brackets_contain_the_roots():
    rng = np.random.default_rng(5)
    for _ in range(200):
        rr = sorted({int(v) for v in rng.integers(-50, 50, rng.integers(1, 7))})
        extra = [(Fraction(int(rng.integers(-5, 5))), Fraction(int(rng.integers(1, 9))))
                 for _ in range(rng.integers(0, 3))]
        c = _poly_from_roots([Fraction(v, 8) for v in rr] + extra)
        f = np.array([float(x) for x in c])
        assert all(Fraction(x) == y for x, y in zip(f, c))  # exactly representable
        br = isolate_real_roots_float(f, None, -7.0, 7.0)
        truth = [v / 8 for v in rr if -7 < v / 8 < 7]
        if br is None:
            continue  # may refuse (e.g. a root exactly at an end), never be wrong
        assert len(br) == len(truth)
        for (a, b, x), t in zip(br, truth):
            assert a <= t <= b and a <= x <= b and abs(x - t) <= 1e-12 * max(1, abs(t))


def test_eigen_verdicts_condition_bound():
    rng = np.random.default_rng(9)
    M = np.stack([np.diag(rng.uniform(0.1, 2, 3)) for _ in range(40)])
    K = np.stack([np.diag(rng.uniform(1e3, 1e6, 3)) + rng.normal(0, 1e3, (3, 3)) for _ in range(40)])
    D = np.stack([np.diag(rng.uniform(-2, 5, 3)) for _ in range(40)])
    codes, mr, _ = eigen_verdicts(M, D, K)
    for i in range(40):
        with mpmath.workdps(40):
            n = 3
            A = mpmath.zeros(6, 6)
            Mi = mpmath.inverse(mpmath.matrix(M[i].tolist()))
            Bk, Bd = -Mi * mpmath.matrix(K[i].tolist()), -Mi * mpmath.matrix(D[i].tolist())
            for a in range(n):
                A[a, n + a] = 1
                for b in range(n):
                    A[n + a, b], A[n + a, n + b] = Bk[a, b], Bd[a, b]
            ref = float(max(z.real for z in mpmath.eig(A, left=False, right=False)))
        if codes[i] != UNDECIDED:
            assert (codes[i] == STABLE) == (ref < 0)
            assert (mr[i] < 0) == (ref < 0)


@pytest.mark.parametrize("preset,tied,x,y,xr,yr", [
    ("paper-fig3", (), "mu1", "mu2", (-0.5, 1.0), (-0.2, 0.9)),
    ("paper-fig2", (), "mu", "k_ip", (-1.0, 1.0), (-1e7, 1e7)),
    ("paper-fig3", (("k_ip2", "8e7"),), "mu1", "k_ip", (-2.0, 2.0), (-1e9, 1e9)),
    ("minimal-model", (("N0", "2000/mu"),), "mu", "Omega", (-1.0, 1.0), (-100.0, 100.0)),
])
def test_map_kernel_has_no_axis_sign_assumption(preset, tied, x, y, xr, yr):
    """Kernel codes on axes through zero / negative values equal the exact rational Routh verdict per point.

    Reference: the closed form evaluated exactly (rational arithmetic) at the
    parameter vector of each point (``space.arrays``), then the exact Routh
    test; the point's validity does not matter here (the kernel must not
    assume the sign of any common denominator).
    """
    from brakesqueal.analysis.robust import exact_trivial_entries

    space = build_space(preset, (), tied)
    k = build(space.model).map_kernel(space, x, y)
    assert k is not None
    ax = {x: np.linspace(*xr, 9), y: np.linspace(*yr, 8)}
    o, i = ax[k.outer], ax[k.inner]
    codes = k.verdicts(o, i)
    arr = space.arrays({k.outer: o[:, None], k.inner: i[None, :]})
    with np.errstate(all="ignore"):
        vec = [np.broadcast_to(v, (o.size, i.size)) for v in space.vectors(arr)]
    checked = 0
    for a in range(o.size):
        for b in range(i.size):
            p = [float(v[a, b]) for v in vec]
            if not all(math.isfinite(v) for v in p):
                continue
            e = exact_trivial_entries(build(space.model), p)
            q = [e[8] * e[11] - e[9] * e[10],
                 e[4] * e[11] + e[8] * e[7] - e[5] * e[10] - e[9] * e[6],
                 e[0] * e[11] + e[4] * e[7] + e[8] * e[3] - e[1] * e[10] - e[5] * e[6] - e[9] * e[2],
                 e[0] * e[7] + e[4] * e[3] - e[1] * e[6] - e[5] * e[2],
                 e[0] * e[3] - e[1] * e[2]]
            if q[4] == 0:
                continue
            ref = routh_exact(q)
            if codes[a, b] != UNDECIDED and ref != UNDECIDED:
                assert codes[a, b] == ref, (o[a], i[b])
                checked += 1
    assert checked > 40


@pytest.mark.parametrize("preset,tied,name,lo,hi,log,fixed", [
    ("paper-fig2", (), "k_ip", 1e-80, 1e80, True, {"mu": 0.6}),
    ("paper-fig2", (), "mu", 0.05, 1.0, False, {"k_ip": 1e8}),
    ("paper-fig3", (("k_ip2", "8e7"),), "mu1", 0.05, 0.95, False, {"Omega": 100.0}),
    ("paper-fig3", (("N0", "60*Omega"),), "Omega", 1e-3, 1e7, True, {}),  # Omega tied: crossings() route
])
@pytest.mark.slow
def test_known_crossings_against_reference(preset, tied, name, lo, hi, log, fixed):
    space = build_space(preset, tuple(fixed.items()), tied)
    r = critical_speeds(space, lo, hi) if name == "Omega" else crossings(space, Axis(name, lo, hi, 2, log))
    assert r.crossings and r.complete
    _check_crossings(space, r, name, log)


def test_numeric_route_is_marked_not_exhaustive():
    base = ParameterSpace.from_preset("paper-fig3", {"k_ip": "inf"}).resolve({})
    space = ParameterSpace.from_parameters(base.replace(h10=0.009))  # breaks eq. 49: non-trivial silent motion
    r = crossings(space, Axis("Omega", 10, 100, 2, True))
    assert not r.exhaustive and "grid" in r.text() and r.to_dict()["exhaustive"] is False
    assert r.crossings
