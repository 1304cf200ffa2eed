"""Issue 10, items 4 and 8: the massless-pad limit of falling friction, and every public call on every model.

A. A massless pad with a finite tangential stiffness ``k_ip`` and a falling friction law keeps a first-order
   pad mode ``lambda = -k_ip / (N0 mu'(Omega r))``.  The same model with a tangential pad mass ``m_p`` (same
   ``k_ip``, no extra damping) must converge to it as ``m_p -> 0``: every eigenvalue of the massless model is
   matched by one of the massive model with an error ``O(m_p)``, the two extra eigenvalues of the massive pads
   run off to ``-N0 mu' / m_p``, and both verdicts are "unstable".  Reference eigenvalues are computed here
   from the pencils assembled from ``M, D, K`` and the descriptor blocks (:func:`pencil_eigenvalues`), and
   ``mu'`` from the laws' formulas written out in this file.

B. For every built-in model, with its default preset: linearize, eigen_analysis (verdict, repr, xarray, plot,
   and the deprecated builder alias of the issue), evaluate_point, crossings (to_dict, text, plot), critical
   speeds, a 6 x 5 stability map, modes along a path, simulate (summary, plot), export to every target and
   Hopf points along the crossing path.  Every verdict is compared with the sign of max Re lambda from an
   independent eigenvalue computation, so a crash or a contradiction fails.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import scipy.linalg as sla
from matplotlib.figure import Figure

from brakesqueal import eigen_analysis
from brakesqueal import linearize
from brakesqueal import Axis
from brakesqueal import modes_along
from brakesqueal import evaluate_point
from brakesqueal import critical_speeds, crossings, stability_map
from brakesqueal.export import TARGETS, export_code
from brakesqueal.model import MODELS, Disk, FrictionLaw, ModelSpec, Pad, ParameterSpace
from brakesqueal.model.library import paper_parameters_full
from brakesqueal import hopf_points
from brakesqueal import simulate


# ----------------------------------------------------------------------------- independent eigenvalues
def pencil_eigenvalues(lm) -> np.ndarray:
    """Eigenvalues of ``E xi' = A xi`` assembled here from a LinearModel's blocks.

    Without pad states: QZ of the pencil (``M`` not inverted).  With pad states (``E`` is regular, but a
    pad's rate coefficient can be 1e-16 of its stiffness at a tilted silent motion, giving |lambda| ~ 1e16):
    the balanced QR algorithm on ``E^-1 A``, whose huge pad modes agree with 60-digit arithmetic to ~1e-15
    (measured; unscaled QZ loses up to 6 digits of them); every eigenvalue's absolute error is then about
    ``eps |lambda|_max``, which the tolerances below allow for.
    """
    n, k = lm.M.shape[0], len(lm.pad_states)
    I, Z = np.eye(n), np.zeros((n, n))
    if k == 0:
        E = np.block([[I, Z], [Z, lm.M]])
        A = np.block([[Z, I], [-lm.K, -lm.D]])
        lam = sla.eigvals(A, E)
        return lam[np.isfinite(lam)]
    Znk, Zkn = np.zeros((n, k)), np.zeros((k, n))
    E = np.block([[I, Z, Znk], [Z, lm.M, lm.R_dL], [Zkn, lm.G_ddQ, lm.G_dL]])
    A = np.block([[Z, I, Znk], [-lm.K, -lm.D, -lm.R_L], [-lm.G_Q, -lm.G_dQ, -lm.G_L]])
    return np.linalg.eigvals(np.linalg.solve(E, A))


def covers(tracked: np.ndarray, lam: np.ndarray, rel: float) -> bool:
    """A mode-tracking row shows the spectrum ``lam``: every tracked value (NaN: none) is an eigenvalue, and
    every eigenvalue with Im >= 0 (one of each conjugate pair, every real one) is tracked."""
    near = lambda z, pool: np.min(np.abs(pool - z)) <= rel * max(abs(z), 1.0)  # noqa: E731
    tracked = tracked[np.isfinite(tracked)]
    upper = lam[lam.imag >= -1e-9 * np.abs(lam)]
    return all(near(z, lam) for z in tracked) and all(near(z, tracked) for z in upper)


def same_spectrum(a: np.ndarray, b: np.ndarray, rel: float) -> bool:
    """Equal multisets of eigenvalues, each to ``rel`` of its modulus (greedy nearest matching)."""
    if a.size != b.size:
        return False
    rest = list(b)
    for z in sorted(a, key=abs, reverse=True):
        j = int(np.argmin([abs(z - w) for w in rest]))
        if abs(z - rest[j]) > rel * max(abs(z), 1.0):
            return False
        rest.pop(j)
    return True


# ============================================================================ A. the massless-pad limit
N0, OMEGA, R = 3600.0, 16 * math.pi, 0.13
V_SLIDE = OMEGA * R  # nominal sliding speed Omega r [m/s]
K_IP = {"1": 1e4, "2": 2e4}  # unequal pads: two distinct pad modes
LAWS = {
    # law: (fields of FrictionLaw, their values, dmu/dv at the sliding speed from the law's formula)
    "falling-linear": ({"slope": "slope"}, {"slope": 0.05}, -0.05),  # mu(v) = mu - slope v
    "stribeck": ({"mu_s": "mu_s", "v_s": "v_s"}, {"mu_s": 0.8, "v_s": 5.0},  # mu + (mu_s - mu) exp(-v/v_s)
                 -(0.8 - 0.5) / 5.0 * math.exp(-V_SLIDE / 5.0)),
    "rising-linear": ({"slope": "slope"}, {"slope": -0.05}, 0.05),  # control: a stable pad mode
}
MASSES = (1e-2, 1e-4, 1e-6)


def _pad_model(law: str, massive: bool) -> ModelSpec:
    fields, values, _ = LAWS[law]
    kind = "stribeck" if law == "stribeck" else "linear"
    extra = {"mass": "m_p", "dofs": ("tangential",)} if massive else {}
    pads = tuple(Pad(n, face, radius="r", k=f"k{n}", d=f"d{n}", preload="N0", k_ip=f"k_ip{n}",
                     friction=FrictionLaw(kind, f"mu{n}", **fields), **extra)
                 for n, face in (("1", "upper"), ("2", "lower")))  # fmt: skip
    par = {**paper_parameters_full(), "k_ip1": K_IP["1"], "k_ip2": K_IP["2"], **values}
    if massive:
        par["m_p"] = MASSES[0]
    return ModelSpec(f"pad-limit-{law}-{'massive' if massive else 'massless'}", Disk(), pads, parameters=par)


@pytest.fixture(scope="module")
def pad_models():
    return {(law, massive): _pad_model(law, massive) for law in LAWS for massive in (False, True)}


@pytest.mark.parametrize("law", list(LAWS))
def test_massive_pads_converge_to_the_massless_pad_modes(pad_models, law):
    dmu = LAWS[law][2]
    spec0, spec1 = pad_models[law, False], pad_models[law, True]
    p0 = spec0.get_preset().resolve({})
    assert (p0["N0"], p0["Omega"], p0["r"]) == (N0, OMEGA, R)
    lm0 = linearize(p0)
    # the massless pads keep their tangential deformation as a first-order state
    assert lm0.n == 2 and lm0.pad_states == ("l1", "l2")
    lam0 = pencil_eigenvalues(lm0)
    assert lam0.size == 2 * 2 + 2
    assert same_spectrum(lam0, lm0.eigenvalues, 1e-9)

    # (ii) the pad modes: lambda = -k_ip / (N0 mu'), up to the disk's coupling (O(1/k_t): checked below)
    real = np.sort(lam0[np.abs(lam0.imag) == 0].real)
    analytic = np.sort([-K_IP[n] / (N0 * dmu) for n in ("1", "2")])
    assert real.size == 2 and np.all(np.sign(real) == np.sign(-dmu))  # positive for a falling law
    assert real == pytest.approx(analytic, rel=1e-3)
    stiff = linearize(spec0.get_preset().resolve({"k_t": 100 * p0["k_t"]}))
    lam_stiff = pencil_eigenvalues(stiff)
    real_stiff = np.sort(lam_stiff[lam_stiff.imag == 0].real)
    dev, dev_stiff = np.abs(real / analytic - 1), np.abs(real_stiff / analytic - 1)
    assert np.all(dev_stiff < 1e-5) and np.all(dev_stiff < dev / 30)  # 100x stiffer disk: ~100x closer

    # (i) O(m_p) convergence of every eigenvalue of the massive model to the massless one's
    errors = []
    for m in MASSES:
        lm1 = linearize(spec1.get_preset().resolve({"m_p": m}))
        assert lm1.n == 4 and lm1.pad_states == () and lm1.coords == ("q1", "q2", "u1", "u2")
        lam1 = pencil_eigenvalues(lm1)
        assert lam1.size == 2 * 4
        assert same_spectrum(lam1, lm1.eigenvalues, 1e-8)
        rest, err = list(lam1), 0.0
        for z in lam0:
            j = int(np.argmin([abs(z - w) for w in rest]))
            err = max(err, abs(z - rest.pop(j)) / abs(z))
        errors.append(err)
        # the two unmatched eigenvalues are the massive pads' fast modes ~ -N0 mu' / m_p: the far roots of each
        # pad's own m_p s^2 + N0 mu' s + k_ip (the disk's coupling shifts them by < 1e-3)
        fast = np.sort(np.array(rest).real)
        assert np.all(np.abs(np.array(rest).imag) == 0)
        own = np.sort([max(np.roots([m, N0 * dmu, K_IP[n]]).real, key=abs) for n in ("1", "2")])
        assert fast == pytest.approx(own, rel=1e-3) and np.all(np.abs(own) > 0.9 * N0 * abs(dmu) / m)
        # (iii) the verdicts
        v0, v1 = eigen_analysis(lm0).verdict(), eigen_analysis(lm1).verdict()
        assert v0.status == v1.status and (v1.status == "unstable") == (float(lam1.real.max()) > 0)
        if dmu < 0:
            assert v0.status == v1.status == "unstable" and lm0.max_real > 0 and lm1.max_real > 0
            assert v0.max_real == pytest.approx(float(lam0.real.max()), rel=1e-9)
    assert errors[-1] < 1e-5, errors
    for big, small in zip(errors, errors[1:]):
        assert small < big / 30, errors  # m_p / 100 -> error / 100 for O(m_p)


# ============================================================================ B. every public call, every model
#: Per model: a path (name, start, stop, log) with at least one stability change, and the axes of a 6 x 5 map
#: with stable and unstable points (unequal pads, non-trivial silent motions and per-point routes included).
PATHS = {
    "paper": (("k_ip1", 1e5, 1e10, True), ("k_ip1", 2e5, 1e10, True), ("mu2", 0.1, 0.9, False)),
    "minimal": (("mu", 0.05, 1.0, False), ("mu", 0.05, 1.0, False), ("d", 0.5, 20.0, False)),
    "in-plane-pad": (("k_ip", 1e5, 1e10, True), ("k_ip", 3e5, 4.2e5, False), ("mu", 0.3, 0.7, False)),
    "six-dof": (("d_t", 0.1, 1e4, True), ("d_t", 0.1, 1e4, True), ("k_c", 1e7, 1e11, True)),
    "eight-dof": (("d1", 0.1, 1e4, True), ("d1", 0.1, 1e4, True), ("m_c", 0.5, 10.0, False)),
    "four-pad": (("mu", 0.05, 1.0, False), ("mu", 0.05, 1.0, False), ("d", 0.5, 40.0, False)),
    "belt": (("slope", -0.1, 0.2, False), ("slope", -0.1, 0.2, False), ("d_ip", 0.15, 15.0, True)),
}
NAMES = list(MODELS)


def test_the_matrix_covers_every_built_in_model():
    assert sorted(PATHS) == sorted(MODELS) and len(MODELS) == 7


_SPACES: dict[str, ParameterSpace] = {}
_CROSSINGS: dict[str, object] = {}


def space_of(name: str) -> ParameterSpace:
    if name not in _SPACES:
        _SPACES[name] = ParameterSpace.from_preset(name)
    return _SPACES[name]


def crossings_of(name: str):
    if name not in _CROSSINGS:
        a = PATHS[name][0]
        _CROSSINGS[name] = crossings(space_of(name), Axis(a[0], a[1], a[2], 2, a[3]))
    return _CROSSINGS[name]


#: Accuracy of eigenvalues relative to their modulus (unscaled QZ vs the library's routes: up to 1e-9 measured,
#: for the six-dof model's stiff contacts).
SPEC_TOL = 1e-8
#: Accuracy of max Re lambda relative to max |lambda| (~3e-11 measured); the least-stable Re lambda of every
#: point checked here is at least 1e-8 |lambda|.
RE_TOL = 1e-9


def reference_max_real(space: ParameterSpace, values: dict[str, float]) -> tuple[float, float]:
    """max Re lambda and its absolute tolerance from independent eigenvalues at a point."""
    lam = pencil_eigenvalues(linearize(space.resolve(values)))
    return float(lam.real.max()), RE_TOL * float(np.abs(lam).max())


def check_point(space: ParameterSpace, values: dict[str, float], stable: bool | None = None) -> bool:
    """evaluate_point is decided there, agrees with independent eigenvalues (and with ``stable`` if given)."""
    pv = evaluate_point(space, values)
    assert pv.decided, (values, pv)
    ref, tol = reference_max_real(space, values)
    assert abs(ref) > tol, (values, ref)  # the reference itself is decided
    assert pv.stable == (pv.max_real < 0) == (ref < 0), (values, pv, ref)
    assert pv.max_real == pytest.approx(ref, abs=tol)
    if stable is not None:
        assert pv.stable == stable, (values, pv)
    return pv.stable


def nearby(value: float, axis: tuple, side: int, frac: float = 1e-3) -> float:
    _, start, stop, log = axis
    return value * math.exp(side * frac) if log else value + side * frac * (stop - start)


@pytest.mark.parametrize("name", NAMES)
def test_linearize_and_eigen_analysis(name):
    import brakesqueal as bs

    space = space_of(name)
    params = space.resolve({})
    lm = linearize(params)
    n, k = lm.n, len(lm.pad_states)
    assert lm.M.shape == lm.D.shape == lm.K.shape == (n, n) and len(lm.coords) == n
    lam = pencil_eigenvalues(lm)
    assert lam.size == 2 * n + k and same_spectrum(lam, lm.eigenvalues, SPEC_TOL)
    d = lm.to_dict()
    json.dumps(d)
    assert d["model"] == name and d["coords"] == list(lm.coords) and len(d["eigenvalues"]) == lam.size

    ea = eigen_analysis(lm)
    assert same_spectrum(ea.eigenvalues, lam, SPEC_TOL) and ea.modes.shape == (n, lam.size)
    v = ea.verdict()
    assert v.status in ("stable", "unstable")
    assert (v.status == "stable") == (v.max_real < 0) == (lam.real.max() < 0)
    assert v.max_real == pytest.approx(float(lam.real.max()), abs=RE_TOL * float(np.abs(lam).max()))
    text = repr(ea)
    assert name in text and v.status in text
    for attr in ("to_dict", "as_dict"):  # whichever the analysis offers must be JSON-ready
        if hasattr(ea, attr):
            json.dumps(getattr(ea, attr)())
    ds = ea.to_xarray()
    assert ds.attrs["verdict"] == v.status and ds["real"].size == lam.size
    fig = ea.plot()
    assert isinstance(fig, Figure) and fig.axes

    # the deprecated builder alias of the issue (it crashed with AttributeError 'as_dict')
    old = bs.eigen_analysis(bs.linearize(bs.get_model(name).get_preset(None).resolve({})))
    assert old.verdict().status == v.status and same_spectrum(old.eigenvalues, lam, SPEC_TOL)


@pytest.mark.parametrize("name", NAMES)
def test_evaluate_point_agrees_with_the_eigenvalues(name):
    space = space_of(name)
    check_point(space, {})
    lm = linearize(space.resolve({}))
    lam = pencil_eigenvalues(lm)
    pv = evaluate_point(space)
    lead = lam[np.argmax(lam.real)]
    assert pv.frequency == pytest.approx(abs(lead.imag) / (2 * math.pi), rel=1e-6, abs=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
def test_crossings_along_a_path(name):
    space = space_of(name)
    axis = PATHS[name][0]
    r = crossings_of(name)
    assert r.parameter == axis[0] and (r.start, r.stop) == (axis[1], axis[2])
    assert len(r.crossings) >= 1  # every chosen path changes stability (see PATHS)
    values = [v for v, _ in r.crossings]
    assert values == sorted(values) and all(axis[1] < v < axis[2] for v in values)
    # the verdict just after the start and on both sides of every crossing, against independent eigenvalues
    check_point(space, {axis[0]: nearby(axis[1], axis, +1, 1e-6)}, r.stable_at_start)
    for v, direction in r.crossings:
        assert direction in ("destabilizing", "stabilizing")
        before = check_point(space, {axis[0]: nearby(v, axis, -1)})
        after = check_point(space, {axis[0]: nearby(v, axis, +1)})
        assert (before, after) == ((True, False) if direction == "destabilizing" else (False, True)), (v, direction)
    # consecutive crossings alternate
    dirs = [d for _, d in r.crossings]
    assert all(a != b for a, b in zip(dirs, dirs[1:]))
    assert (dirs[0] == "destabilizing") == r.stable_at_start
    if name == "belt":  # m u'' + (d_ip - N0 slope) u' + k_ip u = 0: the crossing is at slope = d_ip / N0
        p = space.resolve({})
        assert values == pytest.approx([p["d_ip"] / p["N0"]], rel=1e-9)

    d = r.to_dict()
    json.dumps(d)
    assert d["parameter"] == axis[0] and [c["value"] for c in d["crossings"]] == values
    text = r.text()
    assert axis[0] in text and ("stable at start" in text) and len(text.splitlines()) >= 1 + len(values)
    fig = r.plot()
    assert isinstance(fig, Figure) and fig.axes and fig.axes[0].has_data()


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
def test_critical_speeds(name):
    space = space_of(name)
    assert "Omega" in space.settable()
    r = critical_speeds(space, 1.0, 1e4)
    assert r.parameter == "Omega"
    d = r.to_dict()
    json.dumps(d)
    assert d["Omega_crit"] == r.Omega_crit
    text = r.text()
    assert text.startswith("Omega_crit = ")
    check_point(space, {"Omega": 1.0 * math.exp(1e-6)}, r.stable_at_start)
    for v, direction in r.crossings:
        before = check_point(space, {"Omega": v * math.exp(-1e-3)})
        after = check_point(space, {"Omega": v * math.exp(1e-3)})
        assert (before, after) == ((True, False) if direction == "destabilizing" else (False, True)), (v, direction)
    if r.Omega_crit is None:
        assert not any(dd == "destabilizing" for _, dd in r.crossings)
        assert "none" in text or "UNKNOWN" in text
    else:
        assert f"{r.Omega_crit:.12g}" in text
    if name == "belt":  # mu' = -slope does not depend on the speed: unstable on the whole range
        assert not r.stable_at_start and r.crossings == ()
    else:
        assert r.Omega_crit is not None and 1.0 < r.Omega_crit < 100.0
    fig = r.plot()
    assert isinstance(fig, Figure) and fig.axes


@pytest.mark.parametrize("name", NAMES)
def test_stability_map(name):
    space = space_of(name)
    _, xa, ya = PATHS[name]
    m = stability_map(space, Axis(xa[0], xa[1], xa[2], 6, xa[3]), Axis(ya[0], ya[1], ya[2], 5, ya[3]))
    ds = m.data
    assert ds[xa[0]].size == 6 and ds[ya[0]].size == 5
    assert ds["stable"].shape == ds["status"].shape == ds["max_real"].shape and ds["stable"].size == 30
    status, stable, mr = ds["status"].values, ds["stable"].values, ds["max_real"].values
    decided = (status == 0) | (status == 1)
    assert decided.all(), status  # the chosen ranges are valid everywhere
    assert np.array_equal(stable[decided], mr[decided] < 0)
    assert stable.any() and not stable.all()  # the map crosses the stability boundary
    # every point against independent eigenvalues
    for idx in np.ndindex(mr.shape):
        values = {dim: float(ds[dim].values[i]) for dim, i in zip(ds["stable"].dims, idx)}
        ref, tol = reference_max_real(space, values)
        assert mr[idx] == pytest.approx(ref, abs=tol) and abs(ref) > tol, (values, mr[idx], ref)
        assert bool(stable[idx]) == (ref < 0), values
    fig = m.plot()
    assert isinstance(fig, Figure) and fig.axes


MODES_SPLIT = ("modes_along/track_modes fix the number of columns at the first point and assign the next points' "
               "eigenvalues to them (linear_sum_assignment), so eigenvalues are silently dropped when a complex pair "
               "becomes two real eigenvalues along the path: six-dof, d_t = 0.1..1e4 log, num=7: at d_t = 1e4 the "
               "real eigenvalues -5.82e4 and -6.06e4 are missing from ModeTracks.eigenvalues (6 columns, 8 needed)")


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)  # six-dof: a pair splits into two real eigenvalues (was MODES_SPLIT)
def test_modes_along_the_path(name):
    space = space_of(name)
    pname, start, stop, log = PATHS[name][0]
    tracks = modes_along(space, pname, start, stop, num=7, log=log)
    assert tracks.values.shape == (7,) and tracks.values[0] == pytest.approx(start)
    assert tracks.values[-1] == pytest.approx(stop)
    assert tracks.eigenvalues.shape[0] == 7
    for i in (0, 3, 6):  # one eigenvalue of each conjugate pair, every real one
        ref = pencil_eigenvalues(linearize(space.resolve({pname: float(tracks.values[i])})))
        assert covers(tracks.eigenvalues[i], ref, SPEC_TOL), (i, tracks.eigenvalues[i], ref)
    # the tracked spectrum's stability agrees with the crossings found along the same path ...
    r = crossings_of(name)
    stable = np.nanmax(tracks.eigenvalues.real, axis=1) < 0
    for v, st in zip(tracks.values, stable):
        n_before = sum(c < v for c, _ in r.crossings)
        assert st == (r.stable_at_start == (n_before % 2 == 0)), v
    # ... and a grid interval that changes stability across one crossing has a tracked mode crossing there
    tracked = [c["value"] for c in tracks.crossings]
    for a, b, sa, sb in zip(tracks.values, tracks.values[1:], stable, stable[1:]):
        inside = [c for c, _ in r.crossings if a < c < b]
        if sa != sb and len(inside) == 1:
            assert any(abs(t - inside[0]) <= 1e-6 * abs(inside[0]) for t in tracked), (inside, tracked)
    fig = tracks.plot()
    assert isinstance(fig, Figure) and fig.axes


@pytest.mark.parametrize("name", NAMES)
def test_simulate_short_run(name):
    space = space_of(name)
    params = space.resolve({})
    lm = linearize(params)
    lam = pencil_eigenvalues(lm)
    lead = lam[np.argmax(lam.real)]
    tr = simulate(params, 0.005, method="DOP853")  # SciPy's stepper: no integrator compilation (time)
    assert tr.status == "finished" and tr.model == name
    assert tr.y.shape == (tr.t.size, 2 * lm.n + len(lm.pad_states)) and np.isfinite(tr.y).all()
    assert 0.005 - 1 / tr.sample_rate < tr.t[-1] <= 0.005
    assert tr.coords == lm.coords
    s = tr.summary
    assert s.status == "finished"
    assert s.linear_growth_rate == pytest.approx(lead.real, abs=RE_TOL * abs(lead))
    assert s.linear_frequency_hz == pytest.approx(abs(lead.imag) / (2 * math.pi), rel=1e-8)
    period = 2 * math.pi / abs(lead.imag)
    if period > 0.005:  # the belt (50 Hz): a window shorter than a period gives no estimate, and says so
        assert s.estimate_status == "window-shorter-than-a-period"
        assert math.isnan(s.growth_rate) and math.isnan(s.frequency_hz) and s.warnings
    else:
        # the estimate from the motion agrees with the leading eigenvalue within its own uncertainty (3 sigma)
        assert s.estimate_status == "ok"
        assert abs(s.growth_rate - lead.real) <= 3 * s.growth_rate_stderr
        assert abs(s.frequency_hz - abs(lead.imag) / (2 * math.pi)) <= 3 * s.frequency_stderr + 1e-9
    json.dumps(s.to_dict())
    fig = tr.plot()
    assert isinstance(fig, Figure) and fig.axes


@pytest.mark.parametrize("name", NAMES)
def test_export_to_every_target(name):
    params = space_of(name).resolve({})
    coords = linearize(params).coords
    for what in ("nonlinear", "linear"):
        for target in TARGETS:
            text = export_code(target, what, params)
            assert isinstance(text, str) and len(text) > 500, (target, what)
            assert name in text, (target, what)
            missing = [c for c in coords if c not in text]
            assert not missing, (target, what, missing)


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
def test_hopf_points_along_the_path(name):
    space = space_of(name)
    pname, start, stop, log = PATHS[name][0]
    r = crossings_of(name)
    pts = hopf_points(space, Axis(pname, start, stop, 2, log), result=r)
    assert len(pts) == len(r.crossings)
    for h, (v, direction) in zip(pts, r.crossings):
        assert h.parameter == pname and h.direction == direction
        assert h.value == pytest.approx(v, rel=1e-5)
        json.dumps(h.to_dict())
        assert h.hopf is not None, h.message  # every chosen path crosses with a complex pair
        lam = pencil_eigenvalues(linearize(space.resolve({pname: h.value})))
        crit = lam[np.argmin(np.abs(lam.real))]
        assert abs(crit.real) < 1e-6 * abs(crit)
        assert h.hopf.omega0 == pytest.approx(abs(crit.imag), rel=1e-6)
        assert h.hopf.criticality in ("supercritical", "subcritical", "degenerate")
        assert (h.hopf.dRe_lambda_dp > 0) == (direction == "destabilizing")


# ----------------------------------------------------------------------------- bugs found by the matrix
MODES_MERGE = ("modes_along raises ValueError('the number of modes changes along the path') when two real "
               "eigenvalues merge into a complex pair: belt, slope = -10..0.2, num=5 (overdamped pad at the start)")


@pytest.mark.parametrize("path", [
    ("d_ip", 1.0, 1e4, True),  # was MODES_SPLIT: belt, at d_ip = 1e3 only -114.18 of -114.18, -875.82 was tracked
    ("slope", -10.0, 0.2, False),  # was MODES_MERGE: ValueError when two real eigenvalues merge into a pair
], ids=["split", "merge"])
def test_modes_along_a_path_where_a_pair_splits_or_merges(path):
    """m u'' + (d_ip - N0 slope) u' + k_ip u = 0: a complex pair for |d_ip - N0 slope| < 2 sqrt(k_ip m), else real."""
    space = space_of("belt")
    pname, start, stop, log = path
    tracks = modes_along(space, pname, start, stop, num=5, log=log)
    for v, row in zip(tracks.values, tracks.eigenvalues):
        p = space.resolve({pname: float(v)})
        c = p["d_ip"] - p["N0"] * p["slope"]
        analytic = np.roots([p["m"], c, p["k_ip"]]).astype(complex)
        assert covers(row, analytic, 1e-9), (v, row, analytic)


LOST_MODE = ("LinearModel.eigenvalues (pencil_eigenvalues: equilibrated QZ, infinite eigenvalues dropped) loses a "
             "finite pad mode: paper model, default preset with mu2 = 0.1, k_ip1 = 1e10 (tilted silent motion, "
             "G_dL = diag(-1.9e-16, 3.8e-15)): 5 eigenvalues instead of 6 and lm.max_real = -0.172 (stable), while "
             "eigen_analysis(lm).verdict() and evaluate_point give 'unstable', max_real = 5.222e15, the eigenvalue "
             "of the same pencil in 60-digit arithmetic (mpmath)")


def test_linear_model_keeps_every_finite_eigenvalue_at_a_tilted_silent_motion():
    space = space_of("paper")
    values = {"mu2": 0.1, "k_ip1": 1e10}
    lm = linearize(space.resolve(values))
    assert not lm.silent.trivial and len(lm.pad_states) == 2
    ref = pencil_eigenvalues(lm)  # balanced QR of E^-1 A; agrees with 60-digit arithmetic
    assert ref.size == 2 * 2 + 2 and ref.real.max() > 1e15
    v, pv = eigen_analysis(lm).verdict(), evaluate_point(space, values)
    assert v.status == "unstable" and pv.decided and not pv.stable
    assert pv.max_real == pytest.approx(ref.real.max(), rel=1e-9)
    assert lm.eigenvalues.size == ref.size  # was 5 (LOST_MODE)
    assert lm.max_real == pytest.approx(ref.real.max(), rel=1e-9)  # was -0.172


@pytest.mark.parametrize("seed", range(6))
def test_linear_model_eigenvalues_agree_with_the_certified_verdict_at_random_tilted_points(seed):
    """The class of LOST_MODE: at random tilted silent motions every finite eigenvalue is kept, so max_real and
    the certified verdict never contradict each other (reference: balanced QR of E^-1 A)."""
    rng = np.random.default_rng(seed)
    space = space_of("paper")
    values = {"mu2": float(rng.uniform(0.05, 0.45)), "k_ip1": float(10 ** rng.uniform(6, 11)),
              "k_ip2": float(10 ** rng.uniform(6, 11))}
    lm = linearize(space.resolve(values))
    if lm.silent.trivial or not lm.pad_states:
        pytest.skip("trivial silent motion")
    ref = pencil_eigenvalues(lm)
    assert lm.eigenvalues.size == ref.size
    v = eigen_analysis(lm).verdict()
    if v.status != "undecided":
        assert (v.status == "stable") == (lm.max_real < 0) == (ref.real.max() < 0), (values, lm.max_real, v)
