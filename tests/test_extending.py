"""Extending the toolkit is one module each (``docs/architecture.md``): shown here without touching the package.

Each test does, inside the test, what a developer would add to the one module that owns the thing:

* a friction law — :func:`brakesqueal.model.friction.register_law` (one ``LawDef``): a model file uses it, the
  pads' treatment follows from its declared rate dependence, and the linearization carries its slope;
* a per-point quantity — :func:`brakesqueal.analysis.quantities.register_quantity`: maps (NetCDF) and sweeps
  (Zarr) store it;
* a verdict route — :func:`brakesqueal.analysis.verdict.register`: the dispatcher tries it in its place and
  records it in every result's ``route``.

Every registration is undone (``monkeypatch``), and the expected values come from closed forms written out here.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import brakesqueal as bs
from brakesqueal.analysis import quantities as qmod
from brakesqueal.analysis import verdict as vmod
from brakesqueal.model import friction, resolve_space


# ------------------------------------------------------------------ a friction law
def test_a_new_friction_law_is_one_entry(monkeypatch, tmp_path):
    """``mu(v) = mu (1 - exp(-v / v_c))`` (a rising law near stick): rate dependent, so a massless pad keeps its
    tangential rate; at the trivial silent motion the pad's own mode is ``-G_L / G_dL`` with ``G_dL`` from the
    slope ``mu'(v*) = mu exp(-v*/v_c) / v_c`` at the sliding speed ``v* = Omega r``."""
    law = friction.LawDef(
        "rising", {"v_c": friction.FieldDef("m/s", "creep speed at {owner}", *friction.SPEED_SCALE)},
        lambda sm, v, f: f["mu"] * (1 - sm.exp(-v / f["v_c"])), rate_dependent=True,
        text="mu(v) = mu * (1 - exp(-v / v_c))")
    monkeypatch.setitem(friction._LAWS, "rising", law)
    toml = (
        'name = "rising-pads"\n[disk]\nOmega = "Omega"\n'
        '[[pads]]\nname = "1"\nface = "upper"\nk = "k"\nd = "d"\nk_ip = "k_ip"\n'
        'friction = { law = "rising", mu = "mu", v_c = "v_c" }\n'
        '[[pads]]\nname = "2"\nface = "lower"\nk = "k"\nd = "d"\nk_ip = "k_ip"\n'
        'friction = { law = "rising", mu = "mu", v_c = "v_c" }\n'
        '[parameters]\nTheta = 0.16\nPhi = 0.32\nk_t = 1.88e7\nd_t = 0.1\nh10 = 0.01\nh20 = 0.01\nr = 0.13\n'
        'k = 6e6\nd = 5.0\nN0 = 3600.0\nmu = 0.5\nk_ip = 1e7\nv_c = 5.0\nOmega = 50.0\n')
    f = tmp_path / "rising.toml"
    f.write_text(toml)
    space = resolve_space(str(f))
    spec = space.model
    assert [p.treatment for p in spec.pads] == ["dynamic", "dynamic"]  # from rate_dependent, not from a name
    assert bs.engine(spec).caps.treatment == ("dynamic", "dynamic")
    lm = bs.linearize(space.resolve({}))
    assert set(lm.pad_states) == {"l1", "l2"}
    v = bs.evaluate_point(space)
    assert v.decided and v.method != "none"
    # the pad's own balance (written with the compliance c_ip = 1/k_ip): its rate coefficient is the friction slope
    # term, G_dL = c_ip N0 mu'(v*) in magnitude (nonzero only through the new law)
    p = space.resolve({})
    vstar = p["Omega"] * p["r"]
    slope = p["mu"] * math.exp(-vstar / p["v_c"]) / p["v_c"]
    assert lm.G_dL is not None
    np.testing.assert_allclose(np.abs(np.diag(lm.G_dL)), p["N0"] * slope / p["k_ip"], rtol=1e-9)


# ------------------------------------------------------------------ a per-point quantity
def test_a_new_quantity_is_one_registration(monkeypatch, tmp_path):
    """``decay_time = -1 / max_real`` [s] (where stable): stored by a map and by a sweep."""
    monkeypatch.setattr(qmod, "QUANTITIES", dict(qmod.QUANTITIES))
    qmod.register_quantity(qmod.Quantity(
        "decay_time", "f8", np.nan, {"units": "s", "long_name": "decay time of the least-stable mode"},
        lambda b: np.where(b.verdicts.max_real < 0, -1.0 / b.verdicts.max_real, np.nan), eigen=True))
    space = resolve_space(preset="paper-fig2")
    x, y = bs.Axis("mu", 0.1, 0.6, 6), bs.Axis("k_ip", 1e6, 1e8, 5, True)
    m = bs.stability_map(space, x, y, quantities=("decay_time",)).data
    mr = m["max_real"].values
    want = np.where(mr < 0, -1.0 / mr, np.nan)
    np.testing.assert_allclose(m["decay_time"].values, want, rtol=1e-12)
    assert m["decay_time"].attrs["units"] == "s" and np.isfinite(want).any() and np.isnan(want).any()
    # the NetCDF writer and the sweep's Zarr store take it from the same list
    path = tmp_path / "m.nc"
    bs.write_map(space, x, y, str(path), quantities=("decay_time",))
    import xarray as xr

    with xr.open_dataset(path) as f:
        np.testing.assert_allclose(f["decay_time"].values, want, rtol=1e-12)
    from brakesqueal.sweep import sweep

    ds = sweep({"preset": "paper-fig2", "axes": {"mu": {"values": [0.2, 0.5]}, "k_ip": {"values": [1e6, 1e7]}},
                "compute": {"quantities": ["max_real", "decay_time"]}}, store=str(tmp_path / "s.zarr"))
    mr2 = ds["max_real"].values
    np.testing.assert_allclose(ds["decay_time"].values, np.where(mr2 < 0, -1.0 / mr2, np.nan), rtol=1e-12)


# ------------------------------------------------------------------ a verdict route
class _Mpmath(vmod.Route):
    """A test route: 30-digit eigenvalues of every system, certified by a margin of 1e-8 relative."""

    name = "mpmath-test"
    description = "30-digit eigenvalues (test route)"
    calls = 0

    def applies(self, ctx: vmod.Context) -> bool:
        return True

    def run(self, ctx: vmod.Context, idx: np.ndarray) -> vmod.Result:
        import mpmath

        from brakesqueal.analysis.verdict._linear import linear_groups

        type(self).calls += idx.size
        res = vmod.Result.empty(idx.size)
        pos = {int(i): j for j, i in enumerate(idx)}
        for g in linear_groups(ctx, idx):
            E, A = g.descriptor()
            for q, i in enumerate(g.idx):
                with mpmath.workdps(30):
                    lam = mpmath.eig(mpmath.inverse(mpmath.matrix(E[q].tolist())) * mpmath.matrix(A[q].tolist()))[0]
                top = max(lam, key=lambda z: mpmath.re(z))
                mr = float(mpmath.re(top))
                j = pos[int(i)]
                res.max_real[j], res.frequency[j] = mr, float(abs(mpmath.im(top)) / (2 * math.pi))
                if abs(mr) > 1e-8 * float(abs(top)):
                    res.code[j] = vmod.STABLE if mr < 0 else vmod.UNSTABLE
        return res


@pytest.mark.slow
def test_a_new_verdict_route_is_one_registration(monkeypatch):
    monkeypatch.setattr(vmod._dispatch, "ROUTES", list(vmod.ROUTES))
    vmod._dispatch.register(_Mpmath(), before="eigen-bounds")
    _Mpmath.calls = 0
    space = resolve_space("six-dof")  # no closed form: the linearization's routes decide
    x, y = bs.Axis("mu1", 0.2, 0.8, 4), bs.Axis("k_c", 1e7, 1e9, 3, True)
    from brakesqueal.analysis.maps import stability_map
    from brakesqueal.results import label_names

    m = stability_map(bs.engine(space), space, x, y, boundary=False).data
    names = label_names(m["route"].attrs)
    assert "mpmath-test" in names and _Mpmath.calls > 0
    mine = m["route"].values == names.index("mpmath-test")
    assert mine.any()
    # the route's verdicts agree with the built-in ones
    monkeypatch.undo()
    ref = stability_map(bs.engine(space), space, x, y, boundary=False).data
    np.testing.assert_array_equal(m["stable"].values[mine], ref["stable"].values[mine])
    assert "mpmath-test" not in label_names(ref["route"].attrs)


def test_registering_twice_is_refused(monkeypatch):
    monkeypatch.setattr(vmod._dispatch, "ROUTES", list(vmod.ROUTES))
    with pytest.raises(ValueError, match="registered already"):
        vmod._dispatch.register(vmod.ROUTES[0])
    with pytest.raises(ValueError, match="no route named"):
        vmod._dispatch.register(_Mpmath(), before="no-such-route")
    with pytest.raises(ValueError, match="registered already"):
        qmod.register_quantity(qmod.QUANTITIES["max_real"])
    with pytest.raises(ValueError, match="exists already"):
        friction.register_law(friction.LAWS["coulomb"])
