"""One set of stability routes for every model: map, crossings, critical speeds and sweep on each built-in model.

Every verdict is compared with eigenvalues computed here, independently of
the routes: the linear model of :func:`~brakesqueal.analysis.linear.linearize`
at the point (exact compiled Jacobians; the pads' states kept where they
matter), its first-order form (state matrix of ``M, D, K``, or ``E^-1 A`` of
the descriptor), and the eigenvalues of that matrix — with NumPy where the
relative margin ``|max Re λ| / max |λ|`` is large, in 40-digit mpmath where
it is small.  A decided verdict must agree with the reference wherever the
margin exceeds ``1e-10``; a point may be undecided only where it is below
``1e-6``.  The paper's numbers (Figs. 2 and 3) are checked against the values
published in the paper and documented in ``docs/stability.md``.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

from brakesqueal import critical_speeds, crossings
from brakesqueal import linearize
from brakesqueal import Axis, stability_map
from brakesqueal.errors import BrakesquealError
from brakesqueal.model import MODELS, ParameterSpace, resolve_space

pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")

SAFE = 1e-10
UNDECIDED_OK = 1e-6

#: per model: two map axes, the crossing axis, and the route the model allows along it (maps over mu2 of the
#: paper's model leave eq. 49 at mu2 != mu1: the per-point route there)
CASES = {
    "paper": (Axis("k_ip1", 1e5, 1e10, 5, True), Axis("mu2", 0.3, 0.7, 3), Axis("k_ip1", 1e5, 1e10, 2, True), "closed"),
    "minimal": (Axis("mu", 0.1, 1.0, 5), Axis("Omega", 5.0, 100.0, 4, True), Axis("mu", 0.05, 1.0, 2), "closed"),
    "in-plane-pad": (Axis("k_ip", 1e6, 1e10, 5, True), Axis("mu", 0.1, 1.0, 4), Axis("k_ip", 1e5, 1e10, 2, True),
                     "closed"),
    "four-pad": (Axis("mu", 0.1, 1.0, 5), Axis("d", 0.0, 50.0, 4), Axis("mu", 0.05, 1.0, 2), "closed"),
    "six-dof": (Axis("k_c", 1e7, 1e11, 5, True), Axis("mu1", 0.4, 0.6, 3), Axis("k_c", 1e7, 1e11, 2, True), "points"),
    "eight-dof": (Axis("k_c", 1e8, 1e10, 4, True), Axis("k_cn", 1e6, 1e9, 3, True), Axis("k_cn", 1e6, 1e9, 2, True),
                  "points"),
    "belt": (Axis("slope", 0.0, 0.02, 5), Axis("d_ip", 0.1, 1.0, 3), Axis("slope", 0.0, 0.02, 2), "points"),
}


def test_every_built_in_model_is_covered():
    assert set(CASES) == set(MODELS)


def _first_order(lm):
    """The first-order matrix of the linear model (state matrix, or E^-1 A with the pads' states)."""
    if lm.pad_states:
        E, A = lm.descriptor
        return np.linalg.solve(E, A), (E, A)
    n = lm.n
    Minv = np.linalg.inv(lm.M)
    S = np.zeros((2 * n, 2 * n))
    S[:n, n:] = np.eye(n)
    S[n:, :n] = -Minv @ lm.K
    S[n:, n:] = -Minv @ lm.D
    return S, None


def reference(space, values):
    """``None`` (no usable silent motion or invalid), else ``(max Re λ, relative margin, trivial)``."""
    try:
        lm = linearize(space.resolve(values))
    except BrakesquealError:
        return None
    if lm.pad_states and np.any(np.all(lm.descriptor[0] == 0.0, axis=1)):
        # a kept pad without rate terms (rigid support): algebraic; the finite eigenvalues of the pencil (QZ)
        import scipy.linalg

        E, A = lm.descriptor
        lam = scipy.linalg.eigvals(A, E)
        lam = lam[np.isfinite(lam)]
        return float(lam.real.max()), float(lam.real.max() / np.abs(lam).max()), lm.silent.trivial
    S, desc = _first_order(lm)
    lam = np.linalg.eigvals(S)
    mr = float(lam.real.max())
    rel = mr / float(np.abs(lam).max())
    if abs(rel) < 1e-6:  # small margin: 40 digits from the same float matrices
        with mpmath.workdps(40):
            if desc is None:
                Sm = mpmath.matrix(S.tolist())
            else:
                E, A = desc
                Sm = mpmath.inverse(mpmath.matrix(E.tolist())) * mpmath.matrix(A.tolist())
            ev = mpmath.eig(Sm, left=False, right=False)
            mr = float(max(z.real for z in ev))
            rel = mr / float(max(abs(z) for z in ev))
    return mr, rel, lm.silent.trivial


def check(ref, status, stable, max_real, where):
    if ref is None:
        assert status >= 2 and not stable, where
        return
    mr, rel, trivial = ref
    if status == 5:
        assert abs(rel) < UNDECIDED_OK and not stable, f"{where}: undecided at margin {rel:.3g}"
        return
    assert status == (0 if trivial else 1), f"{where}: status {status}"
    if max_real is not None:
        assert bool(stable) == (max_real < 0), f"{where}: stable contradicts max_real"
    if abs(rel) > SAFE:
        assert bool(stable) == (mr < 0), f"{where}: stable={stable}, reference max Re = {mr:.6g} (rel {rel:.3g})"


CLOSED_ROUTES = {"closed-grid", "closed-interval", "closed-exact"}


def _routes_used(ds):
    """The routes that decided some point of a map (its ``route`` variable)."""
    from brakesqueal.results import label_names

    names = label_names(ds["route"].attrs)
    return {names[int(i)] for i in np.unique(ds["route"].values) if int(i) > 0}


@pytest.mark.slow
@pytest.mark.parametrize("model", list(CASES))
def test_map_and_sweep_against_eigenvalues(model):
    from brakesqueal.sweep import sweep

    x, y, _, route = CASES[model]
    space = resolve_space(model)
    m = stability_map(space, x, y).data
    assert m.attrs["model"] == space.model.name
    map_route = "points" if model == "paper" else route
    used = _routes_used(m)
    if map_route == "closed":
        assert used and used <= CLOSED_ROUTES, used
    else:
        assert "closed-grid" not in used, used  # no grid kernel: the silent motion is not trivial on the whole map
    verdict_only = stability_map(space, x, y, eigen=False).data
    assert "max_real" not in verdict_only and "frequency" not in verdict_only
    ds = sweep({"model": model, "axes": {y.name: {"values": [float(v) for v in y.values()]},
                                         x.name: {"values": [float(v) for v in x.values()]}},
                "compute": {"quantities": ["stable", "max_real", "frequency"]}})
    decided = 0
    for yv in y.values():
        for xv in x.values():
            ref = reference(space, {x.name: float(xv), y.name: float(yv)})
            pt = m.sel({x.name: xv, y.name: yv})
            where = f"{model} {x.name}={xv:.6g} {y.name}={yv:.6g}"
            check(ref, int(pt["status"]), bool(pt["stable"]), float(pt["max_real"]), "map " + where)
            pv = verdict_only.sel({x.name: xv, y.name: yv})
            assert int(pv["status"]) == int(pt["status"]) and bool(pv["stable"]) == bool(pt["stable"]), where
            ps = ds.sel({x.name: xv, y.name: yv})
            assert int(ps["status"]) == int(pt["status"]) and bool(ps["stable"]) == bool(pt["stable"]), where
            np.testing.assert_allclose(float(ps["max_real"]), float(pt["max_real"]), rtol=1e-9, atol=1e-300)
            decided += int(pt["status"]) <= 1
    assert decided >= 0.9 * x.num * y.num


def _sign_changes(space, name, grid):
    refs = [reference(space, {name: float(v)}) for v in grid]
    return refs, [(grid[k], grid[k + 1]) for k in range(len(grid) - 1)
                  if refs[k] and refs[k + 1] and min(abs(refs[k][1]), abs(refs[k + 1][1])) > SAFE
                  and (refs[k][0] < 0) != (refs[k + 1][0] < 0)]


def _check_path(space, r, name, log):
    grid = np.geomspace(r.start, r.stop, 40) if log else np.linspace(r.start, r.stop, 40)
    refs, changes = _sign_changes(space, name, grid)
    values = [v for v, _ in r.crossings]
    assert values == sorted(values)
    for a, b in changes:  # every stability change of the reference is reported (or undecided there)
        inside = [v for v in values if a <= v <= b]
        und = [u for u in r.undecided_ranges if u[0] <= b and u[1] >= a]
        assert len(inside) % 2 == 1 or und, f"{name}: the stability change in [{a:g}, {b:g}] is missing"
    for v, d in r.crossings:  # every reported crossing is a stability change in the stated direction
        for rel in (1e-4, 1e-3, 1e-2):
            eps = rel * abs(v) if v != 0 else rel * (r.stop - r.start)
            before, after = reference(space, {name: v - eps}), reference(space, {name: v + eps})
            if before and after and min(abs(before[1]), abs(after[1])) > SAFE:
                assert (before[0] < 0) != (after[0] < 0), f"{name} = {v}: not a stability change"
                assert (d == "destabilizing") == (before[0] < 0), f"{name} = {v}: wrong direction"
                break
        else:
            pytest.fail(f"{name} = {v}: the crossing could not be checked")
    if r.exhaustive:
        assert "exact" in r.method
    else:
        assert "numeric" in r.method and "grid" in r.text()
    if refs[0] and abs(refs[0][1]) > SAFE and not (values and values[0] < grid[1]):
        assert r.stable_at_start == (refs[0][0] < 0)
    grid_p, prof = r.profile
    assert grid_p.size > 10 and np.all(np.isfinite(prof) | np.isnan(prof))


@pytest.mark.slow
@pytest.mark.parametrize("model", list(CASES))
def test_crossings_against_eigenvalues(model):
    _, _, path, route = CASES[model]
    space = resolve_space(model)
    r = crossings(space, path)
    assert r.exhaustive == (route == "closed")
    _check_path(space, r, path.name, path.log)


@pytest.mark.slow
@pytest.mark.parametrize("model", list(CASES))
def test_critical_speeds_against_eigenvalues(model):
    space = resolve_space(model)
    r = critical_speeds(space, 1.0, 1e3)
    assert r.exhaustive == (CASES[model][3] == "closed")
    if not r.exhaustive:  # a grid search never claims what it has not established
        assert not r.Omega_crit_certain and r.to_dict()["Omega_crit_certain"] is False
        if r.Omega_crit is None:
            assert "UNKNOWN" in r.text() or "unstable already" not in r.text()
    _check_path(space, r, "Omega", True)


@pytest.mark.slow
def test_a_model_file_goes_through_the_same_routes(tmp_path):
    """A TOML model (three Coulomb pads at 120 degrees): closed-form route, verdicts against eigenvalues."""
    from brakesqueal.model import Disk, FrictionLaw, ModelSpec, Pad, model_to_toml

    values = {"Theta": 0.16, "Phi": 0.32, "k_t": 1.88e7, "d_t": 0.1, "h10": 0.01, "h20": 0.01,
              "Omega": 16 * math.pi, "r": 0.13, "k": 6e6, "d": 5.0, "N0": 3600.0, "mu": 0.5}
    spec = ModelSpec("three-pad", Disk(), tuple(
        Pad(f"p{a}", "upper", angle_deg=a, k="k", d="d", preload="N0", friction=FrictionLaw("coulomb", "mu"))
        for a in (0, 120, 240)), parameters=values)
    f = tmp_path / "three.toml"
    f.write_text(model_to_toml(spec))
    space = resolve_space(str(f))
    x, y = Axis("mu", 0.1, 1.0, 4), Axis("Omega", 1.0, 100.0, 4, True)
    m = stability_map(space, x, y).data
    assert _routes_used(m) <= CLOSED_ROUTES and _routes_used(m)
    for yv in y.values():
        for xv in x.values():
            pt = m.sel({x.name: xv, y.name: yv})
            check(reference(space, {x.name: float(xv), y.name: float(yv)}), int(pt["status"]), bool(pt["stable"]),
                  float(pt["max_real"]), f"three-pad mu={xv:g} Omega={yv:g}")
    r = critical_speeds(space, 1.0, 1e3)
    assert r.complete and r.Omega_crit is not None
    _check_path(space, r, "Omega", True)


# ---------------------------------------------------------------- the paper's numbers
def test_fig2_points_A_and_B_are_unchanged():
    """Fig. 2's dashed line mu = 0.5: A (unstable -> stable for decreasing k_ip) and B (stable -> unstable)."""
    r = crossings(ParameterSpace.from_preset("paper-fig2", {"mu": 0.5}), Axis("k_ip", 1e5, 1e10, 2, True))
    assert r.complete and [d for _, d in r.crossings] == ["stabilizing", "destabilizing"]
    (B, _), (A, _) = r.crossings
    assert A == pytest.approx(1.866013e6, rel=1e-6) and B == pytest.approx(2.308813e5, rel=1e-6)


def test_fig3_critical_speed_and_restabilisation_are_unchanged():
    """Fig. 3 at mu1 = mu2 (= 0.5) and k_ip = inf: Omega_crit = 35.60 rad/s; re-stabilisation near 8400 rad/s."""
    r = critical_speeds(ParameterSpace.from_preset("paper-fig3", {"k_ip": "inf", "mu1": 0.5, "mu2": 0.5}), 1.0, 1e5)
    assert r.complete and r.Omega_crit_certain and "exact" in r.method
    assert round(r.Omega_crit, 2) == 35.60
    restab = [v for v, d in r.crossings if d == "stabilizing"]
    assert restab and 8300 < restab[0] < 8500


@pytest.mark.parametrize("model", list(CASES))
def test_grouped_validity_equals_the_roles_table(model):
    """``points.valid_points`` (conditions grouped per array shape) equals ``ParameterSpace.valid`` element-wise."""
    from brakesqueal.analysis.points import valid_points

    space = resolve_space(model)
    rng = np.random.default_rng(7)
    names = list(space.settable())
    for _ in range(20):
        a, b = rng.choice(len(names), 2, replace=False)
        va = space.value(names[a]) * rng.choice([-1.0, 0.0, 0.5, 1.0, 2.0, 1e120, np.nan], 6)
        vb = space.value(names[b]) * rng.choice([-1.0, 0.0, 0.5, 1.0, 2.0, np.inf], 5)
        with np.errstate(all="ignore"):
            arr = space.arrays({names[a]: va[:, None], names[b]: vb[None, :]})
        want = np.broadcast_to(space.valid(arr), (6, 5))
        got = np.broadcast_to(valid_points(space, arr), (6, 5))
        np.testing.assert_array_equal(got, want)


@pytest.mark.slow
def test_critical_speeds_many_batches_trivial_sets_and_routes_the_others_point_by_point():
    """Sets with a trivial silent motion go through the compiled kernel, the others through critical_speeds."""
    from brakesqueal import critical_speeds_many
    from brakesqueal.status import PointStatus

    space = resolve_space("paper", sets={"k_ip1": "inf", "k_ip2": "inf"})
    mu1 = np.array([0.5, 0.52])
    roots, dirs, counts, start, status = critical_speeds_many(space, {"mu1": mu1}, 10.0, 100.0, return_status=True)
    for i, m1 in enumerate(mu1):
        single = critical_speeds(space.with_values({"mu1": float(m1)}), 10.0, 100.0)
        assert counts[i] == len(single.crossings) and bool(start[i]) == single.stable_at_start
        for k, (v, d) in enumerate(single.crossings):
            assert math.isclose(roots[i, k], v, rel_tol=1e-9) and dirs[i, k] == (1 if d == "stabilizing" else -1)
        assert status[i] == (PointStatus.OK if single.complete else PointStatus.UNDECIDED)
    assert status[0] == PointStatus.OK and status[1] == PointStatus.UNDECIDED  # mu1 != mu2: a grid search
    assert counts[0] == 1 and counts[1] >= 1  # the onset of squeal near 35 rad/s in both
    _check_path(space.with_values({"mu1": 0.52}), critical_speeds(space.with_values({"mu1": 0.52}), 10.0, 100.0),
                "Omega", True)
