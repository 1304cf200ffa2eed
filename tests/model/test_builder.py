"""Built-in and custom models through the one engine: limits, symmetry, classic criteria, bad input.

(The former builder-versus-engine comparisons are gone: there is one engine.)
"""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from brakesqueal import linearize
from brakesqueal.errors import ParameterError
from brakesqueal.model import MODELS, Caliper, Disk, FrictionLaw, ModelSpec, Pad, get_model, model_to_toml, spec_from_dict


def linearize_model(spec, overrides=None):
    """The linear model of ``spec`` at its default values with ``overrides`` (the unified engine)."""
    return linearize(spec.get_preset().resolve(dict(overrides or {})))


def _slow_eigs(lm, k=4):
    lam = lm.eigenvalues
    return np.sort_complex(lam[np.argsort(np.abs(lam))][:k])


def test_extended_models_converge_to_2dof_as_pad_masses_vanish():
    ref = np.sort_complex(linearize_model(get_model("paper-2dof")).eigenvalues)
    errs = []
    for m_p, k_c in ((1e-2, 1e10), (1e-4, 1e12), (1e-6, 1e14)):
        six = linearize_model(get_model("six-dof"), {"m_p": m_p, "k_c": k_c})
        assert six.M.shape == (6, 6)
        errs.append(np.max(np.abs(_slow_eigs(six) - ref) / np.abs(ref)))
    assert errs[0] > errs[1] > errs[2] and errs[2] < 1e-6, errs
    # the real parts (stability!) converge too
    six = linearize_model(get_model("six-dof"), {"m_p": 1e-6, "k_c": 1e14})
    assert np.allclose(_slow_eigs(six).real, ref.real, rtol=1e-3)


def test_eight_dof_caliper_limit():
    """A stiffer, lighter caliper makes the 8-DOF model converge to the 6-DOF one.

    The caliper springs act in series with the pads' supports, so the slow eigenvalues differ from
    the 6-DOF ones by O(k_pad / k_caliper): the error must fall with each step of the limit (a fixed
    tolerance at one step would only test the round-off of the last digits).
    """
    ref = _slow_eigs(linearize_model(get_model("six-dof")), 6)
    errs = []
    for m_c, k in ((1e-2, 1e10), (1e-4, 1e12), (1e-6, 1e14)):
        eight = linearize_model(get_model("eight-dof"), {"m_c": m_c, "k_cn": k, "k_ct": k})
        assert eight.M.shape == (8, 8)
        errs.append(np.max(np.abs(_slow_eigs(eight, 6) - ref) / np.abs(ref)))
    assert errs[0] > 10 * errs[1] > 100 * errs[2] and errs[2] < 1e-5, errs


@pytest.mark.parametrize("factor", [0.97, 1.03])
def test_mass_on_belt_recovers_negative_slope_criterion(factor):
    """m u'' + (d_ip + N0 dmu/dv) u' + k u = 0: unstable iff d_ip < N0 * slope (ref. [1])."""
    spec = get_model("belt")
    v = spec.parameters
    slope = factor * v["d_ip"] / v["N0"]
    lm = linearize_model(spec, {"slope": slope})
    c_eff = v["d_ip"] - v["N0"] * slope
    expected = -c_eff / (2 * v["m"])
    assert lm.M.shape == (1, 1)
    assert math.isclose(lm.max_real, expected, rel_tol=1e-9)
    assert (lm.max_real > 0) == (factor > 1)
    assert math.isclose(abs(lm.eigenvalues[0].imag), math.sqrt(v["k_ip"] / v["m"] - expected**2), rel_tol=1e-9)


def test_four_equal_pads_behave_symmetrically():
    lm = linearize_model(get_model("four-pad"))
    J = np.array([[0.0, -1.0], [1.0, 0.0]])  # a quarter turn maps the tilt (q1, q2) to (-q2, q1)
    for m in (lm.M, lm.D, lm.K):
        assert np.allclose(J @ m, m @ J, rtol=0, atol=1e-9 * np.abs(m).max())
    # sanity: three pads are not symmetric under a quarter turn
    spec = get_model("four-pad")
    three = ModelSpec("three", spec.disk, spec.pads[:3], parameters=spec.parameters)
    K3 = linearize_model(three).K
    assert not np.allclose(J @ K3, K3 @ J, rtol=0, atol=1e-6 * np.abs(K3).max())


@pytest.mark.parametrize("name", list(MODELS))
def test_toml_round_trip(name, tmp_path):
    spec = get_model(name)
    text = model_to_toml(spec)
    assert spec_from_dict(tomllib.loads(text)) == spec


def _pad(**kw):
    base = dict(name="a", face="upper", friction=FrictionLaw("coulomb", "mu"))
    base.update(kw)
    return Pad(**base)


_NUM_DISK = Disk(Theta=0.16, Phi=0.32, k_t=1e7, d_t=0.1, h_upper=0.01, h_lower=0.01, Omega=50.0, radius=0.15)


def _num_pad(**kw):
    return _pad(k=6e6, d=5.0, preload=3000.0, **kw)


BAD = [
    (lambda: ModelSpec("m", _NUM_DISK, (_num_pad(radius=0.2),), parameters={"mu": 0.4}), "pad 'a'.*off the disk"),
    (lambda: _pad(dofs=("tangential",)).validate(), "pad 'a'.*without mass"),
    (lambda: _pad(mass=1.0, dofs=("tangential",)).validate(), "pad 'a'.*tangential DOF without stiffness"),
    (lambda: ModelSpec("m", _NUM_DISK, (_num_pad(radius=0.1, friction=FrictionLaw("coulomb", -0.3)),)),
     "pad 'a'.*mu .*must be in \\[0, inf\\)"),
    (lambda: _pad(friction=FrictionLaw("stribeck", 0.3)).validate(), "pad 'a'.*needs 'mu_s'"),
    (lambda: ModelSpec("m", _NUM_DISK, (_num_pad(radius=0.1, friction=FrictionLaw("coulomb", 0.3), mount="c"),),
                       calipers=(Caliper("c", mass=1.0, k_n=0.0, k_t=1.0),)),
     "caliper 'c'.*positive stiffness"),
    (lambda: ModelSpec("m", Disk(), (_pad(), _pad()), parameters={}), "duplicate component name 'a'"),
    (lambda: _pad(mass=1.0, dofs=("normal",)).validate(), "normal DOF needs a contact stiffness"),
]


@pytest.mark.parametrize("make,pattern", BAD, ids=[p for _, p in BAD])
def test_bad_components_are_named(make, pattern):
    with pytest.raises(ParameterError, match=pattern):
        make()


def test_bad_parameter_values_are_named():
    with pytest.raises(ParameterError, match="'m_p'.*must be in \\(0, inf\\)"):
        linearize_model(get_model("six-dof"), {"m_p": 0.0})
    with pytest.raises(ParameterError, match="'mu1'.*\\[0, inf\\)"):
        linearize_model(get_model("paper-2dof"), {"mu1": -0.1})
    with pytest.raises(ParameterError, match="'zzz'"):
        linearize_model(get_model("paper-2dof"), {"zzz": 1.0})


def test_silent_motion_converges_when_residual_reaches_rounding_level():
    """Regression: a three-pad Stribeck model whose Newton step stalled just above an absolute tolerance."""
    from brakesqueal.codegen import compile_model
    from brakesqueal.model.library import paper_parameters

    pads = (
        Pad("1", "upper", k="k1", d="d1", preload="N0", k_ip="k_ip1",
            friction=FrictionLaw("stribeck", "mu1", mu_s="mu_s", v_s="v_s")),
        Pad("2", "lower", k="k2", d="d2", preload="N0", k_ip="k_ip2",
            friction=FrictionLaw("stribeck", "mu2", mu_s="mu_s", v_s="v_s")),
        Pad("3", "upper", angle_deg=180, k="k3", d="d1", preload="N3", friction=FrictionLaw("coulomb", "mu3")),
    )  # fmt: skip
    par = {**paper_parameters(), "r": 0.13, "k1": 6e6, "k2": 6e6, "d1": 5.0, "d2": 5.0, "N0": 3600.0, "mu1": 0.5,
           "mu2": 0.5, "k_ip1": 1e8, "k_ip2": 1e8, "mu_s": 0.6, "v_s": 1.0, "k3": 3e6, "N3": 1000.0, "mu3": 0.4}
    spec = ModelSpec("three-pad-stribeck", Disk(), pads, parameters=par)
    params = spec.get_preset().resolve({"Omega": 1.19377, "mu_s": 0.55833})
    lm = linearize(params)
    cm = compile_model(spec)
    res = np.array(cm.residuals(lm.silent.state(), list(params.vector())))
    Q0 = lm.silent.q0
    assert np.abs(Q0).max() > 1e-7 and np.abs(res[:2]).max() < 1e-9 * par["k_t"] * np.abs(Q0).max()
