"""Speed-dependent friction laws at extreme sliding speeds and speed scales: finite numbers and a verdict.

The Stribeck decay ``exp(-v/v_s)`` overflowed at high sliding speeds: SymPy's
``cancel`` (used to simplify the pads' rate terms at the zero state) wrote it
as ``1/exp(v/v_s)`` and multiplied the other terms by ``exp(v/v_s)``, so the
generated code evaluated ``inf/inf`` once ``v/v_s > 709`` (``linearize
--model stribd.toml --set Omega=18927 --set vs=1.81`` died with a
``LinAlgError``).  :func:`brakesqueal.symbolic.linearize.simplify_entry` keeps
exponentials in the numerators.  The speed scales ``v_s`` and ``v_reg`` are
limited to ``(1e-50, 1e50)`` m/s (``v/v_s^2`` and ``v_reg^4`` of the generated
code overflowed beyond).

Independent check: about the trivial silent motion the linear model depends on
the friction law only through ``mu(v*)`` and ``mu'(v*)`` at the nominal speed
``v* = Omega r``.  Both are evaluated here with mpmath (50 digits, the law
written out by hand, its derivative by ``mpmath.diff``) and put into a model
with the *linear* law ``mu_L - s v`` (``s = -mu'(v*)``, ``mu_L = mu(v*) + s v*``),
compiled separately: its descriptor matrices must equal those of the Stribeck
(or stick) model.  Where ``exp(-v*/v_s)`` underflows this is the limit law
without the Stribeck term.

``STRIBD`` is the adversarial tester's model file ``/tmp/advA/stribd.toml``
(the paper's supports with Stribeck friction on both massless pads, which
carry a tangential damper ``dip``), copied verbatim.
"""

from __future__ import annotations

import math
import warnings

import mpmath
import numpy as np
import pytest

from brakesqueal import linearize
from brakesqueal import evaluate_point
from brakesqueal.analysis.points import linear_verdict
from brakesqueal.analysis.robust import STABLE, UNDECIDED, UNSTABLE
from brakesqueal.cli import main
from brakesqueal.codegen import compile_model
from brakesqueal.errors import ParameterError
from brakesqueal.model.friction import LAWS, SPEED_SCALE
from brakesqueal.model.io import load_model
from brakesqueal.model.parameters import ParameterSpace
from brakesqueal.status import PointStatus

STRIBD = '''name = "stribd"
description = "paper-like with Stribeck friction on both massless pads"
[parameters]
Theta = 0.16
Phi = 0.32
k_t = 18800000.0
d_t = 0.1
k1 = 6000000.0
k2 = 6000000.0
d1 = 5.0
d2 = 5.0
k_ip1 = 100000000.0
k_ip2 = 100000000.0
mu1 = 0.4
mu2 = 0.4
mus = 0.6
vs = 2.0
dip = 20.0
h10 = 0.01
h20 = 0.01
r = 0.13
N0 = 3600.0
Omega = 50.0

[disk]
Theta = "Theta"
Phi = "Phi"
k_t = "k_t"
d_t = "d_t"
h_upper = "h10"
h_lower = "h20"
Omega = "Omega"
radius = "inf"
tilting = true

[[pads]]
name = "1"
face = "upper"
angle_deg = 0.0
radius = "r"
k = "k1"
d = "d1"
preload = "N0"
k_ip = "k_ip1"
d_ip = "dip"
friction = { law = "stribeck", mu = "mu1", mu_s = "mus", v_s = "vs" }

[[pads]]
name = "2"
face = "lower"
angle_deg = 0.0
radius = "r"
k = "k2"
d = "d2"
preload = "N0"
k_ip = "k_ip2"
d_ip = "dip"
friction = { law = "stribeck", mu = "mu2", mu_s = "mus", v_s = "vs" }
'''

_STRIBECK_PARAMS = "mu1 = 0.4\nmu2 = 0.4\nmus = 0.6\nvs = 2.0\n"
_STRIBECK_LAW = 'friction = { law = "stribeck", mu = "mu%s", mu_s = "mus", v_s = "vs" }'


def _variant(name: str, params: str, law: str) -> str:
    """STRIBD with other friction parameters and law (``law`` with ``%s`` for the pad's number)."""
    text = STRIBD.replace('name = "stribd"', f'name = "{name}"').replace(_STRIBECK_PARAMS, params)
    for pad in ("1", "2"):
        text = text.replace(_STRIBECK_LAW % pad, law.replace("%s", pad))
    return text


STICKD = _variant("stickd", "mu1 = 0.4\nmu2 = 0.4\nsl = 0.001\nvreg = 0.01\n",
                  'friction = { law = "stick", mu = "mu%s", v_reg = "vreg", slope = "sl" }')
LIND = _variant("lind", "muL = 0.4\nsL = 0.0\n", 'friction = { law = "linear", mu = "muL", slope = "sL" }')


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    d = tmp_path_factory.mktemp("friction-models")
    out = {}
    for name, text in (("stribd", STRIBD), ("stickd", STICKD), ("lind", LIND)):
        path = d / f"{name}.toml"
        path.write_text(text)
        out[name] = (str(path), load_model(str(path)))
    return out


def _space(models, name: str) -> ParameterSpace:
    spec = models[name][1]
    return ParameterSpace.from_preset(spec.name, model=spec)


# ------------------------------------------------------------------ mpmath: the laws written out by hand
# (50 digits inside _linear_twin only: a module-level mpmath.mp.dps would change every later test in the process)


def _mu_stribeck(v, mu, mus, vs):
    return mu + (mus - mu) * mpmath.exp(-v / vs)


def _mu_stick(v, mu, vreg, slope):
    return v * (mu / mpmath.sqrt(v * v + vreg * vreg) - slope)


def _linear_twin(mu_of_v, v_star: float) -> dict[str, float]:
    """``muL``, ``sL`` of the linear law with the same value and slope at ``v*`` (mpmath, 50 digits)."""
    with mpmath.workdps(50):
        v = mpmath.mpf(v_star)
        s = -mpmath.diff(mu_of_v, v)
        return {"muL": float(mu_of_v(v) + s * v), "sL": float(s)}


def _check_finite_verdict(lm) -> tuple[int, float]:
    lam = lm.eigenvalues
    assert lam.size and np.all(np.isfinite(lam)), lam
    code, max_real, freq = linear_verdict(lm)
    assert code in (STABLE, UNSTABLE, UNDECIDED) and math.isfinite(max_real) and math.isfinite(freq)
    return code, max_real


def _compare_descriptors(lm, twin) -> None:
    assert lm.pad_states == twin.pad_states
    for a, b in zip(lm.descriptor, twin.descriptor):
        scale = np.max(np.abs(a), axis=1, keepdims=True)  # per row: entries of one equation
        assert np.all(np.abs(a - b) <= 1e-9 * scale + 1e-12), (a, b)


def _draws(rng, n: int) -> list[tuple[float, float]]:
    lo = math.log10(SPEED_SCALE[0])
    return [(18927.0, 1.81), (1e6, 10 ** (lo + 1e-9))] + [
        (float(10 ** rng.uniform(0, 6)), float(10 ** rng.uniform(lo + 1e-9, 3))) for _ in range(n)]


@pytest.mark.slow
def test_stribeck_at_any_slip_speed_matches_mpmath(models, rng) -> None:
    space, twin = _space(models, "stribd"), _space(models, "lind")
    r = space.value("r")
    for omega, vs in _draws(rng, 14):
        mu, mus = float(rng.uniform(0.2, 0.6)), float(rng.uniform(0.1, 0.8))
        params = space.resolve({"Omega": omega, "vs": vs, "mu1": mu, "mu2": mu, "mus": mus})
        lm = linearize(params)
        code, max_real = _check_finite_verdict(lm)
        ref = _linear_twin(lambda v: _mu_stribeck(v, mpmath.mpf(mu), mpmath.mpf(mus), mpmath.mpf(vs)), omega * r)
        if omega * r / vs > 800:  # exp(-v*/v_s) underflows: the limit law without the Stribeck term
            assert ref == {"muL": mu, "sL": 0.0}
        tw = linearize(twin.resolve({"Omega": omega, **ref}))
        _compare_descriptors(lm, tw)
        tcode, tmax = _check_finite_verdict(tw)
        assert max_real == pytest.approx(tmax, rel=1e-6, abs=1e-9 * float(np.max(np.abs(lm.eigenvalues))))
        if UNDECIDED not in (code, tcode):
            assert code == tcode


def test_stick_law_at_any_slip_speed_and_regularisation_matches_mpmath(models, rng) -> None:
    space, twin = _space(models, "stickd"), _space(models, "lind")
    r = space.value("r")
    for omega, vreg in _draws(rng, 8) + [(1e3, 0.99e50)]:
        mu, sl = float(rng.uniform(0.2, 0.6)), float(rng.uniform(-1e-3, 1e-3))
        lm = linearize(space.resolve({"Omega": omega, "vreg": vreg, "mu1": mu, "mu2": mu, "sl": sl}))
        _check_finite_verdict(lm)
        ref = _linear_twin(lambda v: _mu_stick(v, mpmath.mpf(mu), mpmath.mpf(vreg), mpmath.mpf(sl)), omega * r)
        _compare_descriptors(lm, linearize(twin.resolve({"Omega": omega, **ref})))


def test_generated_zero_state_functions_stay_finite(models, rng) -> None:
    """Every generated zero-state function (residuals, Jacobians, scales) is finite over the allowed ranges."""
    for name, speed in (("stribd", "vs"), ("stickd", "vreg")):
        space = _space(models, name)
        cm = compile_model(models[name][1])
        for omega, vs in _draws(rng, 10):
            p = space.resolve({"Omega": omega, speed: vs}).vector()
            for fn in ("zero_residuals", "zero_jacobians", "zero_residual_scale"):
                f = getattr(cm.vectorized, fn)
                with warnings.catch_warnings():
                    warnings.simplefilter("error")  # no overflow, no invalid value
                    vals = f([np.array([x]) for x in p])
                assert all(np.all(np.isfinite(np.asarray(v, dtype=float))) for v in vals), (name, fn, omega, vs)
                # Python floats (zero_jacobian_matrix): an overflowing power raises OverflowError there
                assert all(math.isfinite(float(v)) for v in f([float(x) for x in p])), (name, fn, omega, vs)


def test_simplify_entry_keeps_decays_in_the_numerators() -> None:
    import sympy as sp

    from brakesqueal.symbolic.linearize import simplify_entry

    v, vs, mu, mus, N0, dip, c = sp.symbols("v vs mu mus N0 dip c", positive=True)
    decay = sp.exp(-v / vs)
    e = c * (N0 * sp.diff(mu + (mus - mu) * decay, v) + vs * dip) / vs + mu * decay / (1 + c)
    plain, kept = sp.factor_terms(sp.cancel(e)), simplify_entry(e)
    assert any(not a.args[0].could_extract_minus_sign() for a in plain.atoms(sp.exp))  # the defect's source
    assert all(a.args[0].is_nonpositive for a in kept.atoms(sp.exp))
    vals = {v: 2000.0, vs: 1.0, mu: 0.4, mus: 0.6, N0: 3600.0, dip: 20.0, c: 1e-8}
    exact = sp.N(e.subs(vals), 30)
    with np.errstate(all="ignore"):
        assert not np.isfinite(sp.lambdify(list(vals), plain, "numpy")(*vals.values()))
        assert sp.lambdify(list(vals), kept, "numpy")(*vals.values()) == pytest.approx(float(exact), rel=1e-14)
    x = sp.Symbol("x", positive=True)
    assert simplify_entry((x**2 - 1) / (x - 1)) == x + 1  # without exponentials: factor_terms(cancel(e))
    assert sp.simplify(simplify_entry(e) - e) == 0


@pytest.mark.parametrize("law,field", [("stribeck", "v_s"), ("stick", "v_reg")])
def test_speed_scales_are_bounded(law: str, field: str) -> None:
    f = LAWS[law].fields[field]
    assert (f.low, f.high, f.low_open, f.high_open) == SPEED_SCALE


@pytest.mark.parametrize("name,value", [("vs", "1e-60"), ("vs", "1e-50"), ("vs", "1e60"), ("vs", "0")])
def test_cli_refuses_speed_scales_outside_the_range(models, capsys, name: str, value: str) -> None:
    rc = main(["linearize", "--model", models["stribd"][0], "--set", f"{name}={value}"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and f"'{name}'" in err[0] and "(1e-50, 1e+50) m/s" in err[0], err


def test_cli_decides_the_adversarial_point(models, capsys) -> None:
    rc = main(["linearize", "--model", models["stribd"][0], "--set", "Omega=18927", "--set", "vs=1.81"])
    out = capsys.readouterr().out
    assert rc == 0 and "Silent motion is stable" in out, out


def test_parameter_space_refuses_tiny_stribeck_speed(models) -> None:
    space = _space(models, "stribd")
    with pytest.raises(ParameterError, match=r"'vs'.*\(1e-50, 1e\+50\)"):
        space.resolve({"vs": 1e-300})
    arr = space.arrays({"vs": np.array([1e-300, 1.0, 1e300])})
    assert space.valid(arr).tolist() == [False, True, False]


def test_point_route_decides_the_adversarial_point(models) -> None:
    pv = evaluate_point(_space(models, "stribd"), {"Omega": 18927.0, "vs": 1.81})
    assert pv.status == PointStatus.OK and pv.stable and math.isfinite(pv.max_real)
