"""``inf`` where a role allows it: a clean verdict or one ParameterError, never another exception.

A pad's tangential stiffness ``k_ip`` may be ``inf`` (a rigid support): a
massless pad then moves with its support.  A pad with a tangential DOF has its
own tangential coordinate, which a rigid support would remove; there ``inf``
crashed the generated code (``c_ip**(-1)`` at ``c_ip = 0``).  The role of
``k_ip`` now depends on the pad (``finite_if`` of :func:`brakesqueal.model.components.param`),
so every channel refuses it: the scalar checks (``--set``, parameter files),
the array checks of maps and sweeps (``ParameterSpace.valid``,
``roles.valid_mask``, ``points.valid_points``: such cells are INVALID), and
the CLI commands (exit status 2, one line naming the parameter, the pad and
the range).

The randomized test sets random subsets of every parameter whose field allows
``inf`` (by the field's own interval, :data:`brakesqueal.model.roles.ROLES`)
to ``inf`` in every built-in model and requires either a ParameterError or a
verdict whose numbers agree with the eigenvalues.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from brakesqueal import linearize
from brakesqueal import evaluate, evaluate_point
from brakesqueal.analysis.points import linear_verdict, valid_points
from brakesqueal.analysis.robust import STABLE, UNDECIDED, UNSTABLE
from brakesqueal.cli import main
from brakesqueal.errors import ParameterError
from brakesqueal.model import get_model
from brakesqueal.model.library import MODELS
from brakesqueal.model.parameters import ParameterSpace
from brakesqueal.model.roles import ROLES, valid_mask
from brakesqueal.status import PointStatus


def _inf_names(spec) -> list[str]:
    """Parameter names every one of whose fields allows ``inf`` by the field's own interval."""
    out = []
    for name in spec.parameter_names():
        keys = {role.key for role, _ in spec.roles().uses.get(name, ())}
        if keys and all(ROLES[k].allows_inf for k in keys):
            out.append(name)
    return out


def _tangential_dof_names(spec) -> list[tuple[str, str]]:
    """``(k_ip name, pad)`` of the pads with a tangential DOF and a named ``k_ip``."""
    return [(p.k_ip, p.name) for p in spec.pads if "tangential" in p.dofs and isinstance(p.k_ip, str)]


CASES = [(m, n, pad) for m in MODELS for n, pad in _tangential_dof_names(get_model(m))]


def test_cases_cover_the_models_with_pad_masses() -> None:
    assert {m for m, _, _ in CASES} == {"six-dof", "eight-dof", "belt"}


@pytest.mark.parametrize("model,name,pad", CASES, ids=[f"{m}-{n}" for m, n, _ in CASES])
def test_role_of_k_ip_depends_on_the_pad(model: str, name: str, pad: str) -> None:
    spec = get_model(model)
    roles = spec.roles()
    assert not roles.allows_inf(name)
    assert roles.interval(name) == "(0, inf)"
    (role, owner), = roles.uses[name]
    assert role.key == "pad.k_ip" and f"pad '{pad}'" in owner and "tangential DOF" in role.finite
    assert ROLES["pad.k_ip"].allows_inf  # the field itself still allows a rigid support (massless pads)
    space = ParameterSpace.from_preset(model, model=spec)
    with pytest.raises(ParameterError) as e:
        space.resolve({name: math.inf})
    msg = str(e.value)
    assert "\n" not in msg and f"'{name}'" in msg and f"pad '{pad}'" in msg and "(0, inf) N/m" in msg
    assert "tangential DOF" in msg and msg.endswith("got inf")
    # a large finite stiffness is still a valid value
    space.resolve({name: 1e12})


def test_massless_pads_keep_the_rigid_support() -> None:
    for model in ("paper", "in-plane-pad"):
        spec = get_model(model)
        for name in _inf_names(spec):
            assert spec.roles().allows_inf(name)
            assert not spec.roles().uses[name][0][0].finite
    assert {n for n in _inf_names(get_model("paper"))} == {"k_ip1", "k_ip2"}


@pytest.mark.parametrize("model,name,pad", CASES, ids=[f"{m}-{n}" for m, n, _ in CASES])
def test_array_validation_marks_rigid_cells_invalid(model: str, name: str, pad: str) -> None:
    spec = get_model(model)
    space = ParameterSpace.from_preset(model, model=spec)
    vals = np.array([1e6, math.inf, 1e8, math.inf])
    arr = space.arrays({name: vals})
    want = np.isfinite(vals)
    assert np.array_equal(space.valid(arr), want)
    assert np.array_equal(valid_mask(spec.roles(), arr), want)
    assert np.array_equal(np.broadcast_to(valid_points(space, arr), want.shape), want)
    pts = evaluate(space, {name: vals})
    assert np.array_equal(pts.status == PointStatus.INVALID, ~want)
    assert np.all(np.isin(pts.status[want], (PointStatus.OK, PointStatus.OK_NONTRIVIAL)))
    assert np.all(np.isfinite(pts.max_real[want])) and not pts.stable[~want].any()
    assert evaluate_point(space, {name: math.inf}).status == PointStatus.INVALID


def _run(capsys, *args: str) -> tuple[int, list[str]]:
    rc = main(list(args))
    return rc, capsys.readouterr().err.strip().splitlines()


@pytest.mark.parametrize("command", [
    ["linearize"], ["eigen"], ["simulate", "--t-end", "0.01"], ["export", "--to", "python", "--out", "{tmp}/m.py"],
    ["map", "--x", "mu1=0.3:0.5:2", "--y", "N0=1000:2000:2", "--out", "{tmp}/m.nc"],
])
@pytest.mark.parametrize("model,name", [("belt", "k_ip"), ("six-dof", "k_ip1"), ("eight-dof", "k_ip2")])
def test_cli_refuses_rigid_support_of_pad_mass(capsys, tmp_path, command: list[str], model: str, name: str) -> None:
    args = [a.replace("{tmp}", str(tmp_path)) for a in command]
    if model == "belt" and args[0] == "map":
        args[2], args[4] = "mu=0.3:0.5:2", "N0=1000:2000:2"
    rc, err = _run(capsys, *args, "--model", model, "--set", f"{name}=inf")
    assert rc == 2 and len(err) == 1, err
    assert f"'{name}'" in err[0] and "(0, inf)" in err[0] and "tangential DOF" in err[0], err


def test_literal_rigid_support_of_pad_mass_is_refused() -> None:
    from brakesqueal.model.components import Pad

    with pytest.raises(ParameterError, match=r"pad 'a'.*tangential DOF"):
        Pad("a", "upper", mass=1.0, dofs=("tangential",), k_ip=math.inf).validate()
    Pad("a", "upper", mass=1.0, dofs=("normal",), k_c="k_c", k_ip=math.inf).validate()  # massless tangentially


def _check_verdict(params) -> None:
    lm = linearize(params)
    lam = lm.eigenvalues
    assert lam.size and np.all(np.isfinite(lam))
    code, max_real, freq = linear_verdict(lm)
    assert code in (STABLE, UNSTABLE, UNDECIDED) and math.isfinite(max_real) and math.isfinite(freq)
    assert max_real == pytest.approx(float(np.max(lam.real)), rel=1e-6, abs=1e-6 * float(np.max(np.abs(lam))))
    if code == STABLE:
        assert max_real < 0
    elif code == UNSTABLE:
        assert max_real > 0


@pytest.mark.parametrize("model", MODELS)
def test_inf_wherever_a_field_allows_it(model: str, rng) -> None:
    """Random subsets of the inf-capable names at inf (others random finite): a ParameterError or a verdict."""
    spec = get_model(model)
    names = _inf_names(spec)
    space = ParameterSpace.from_preset(model, model=spec)
    free = set(space.settable())
    names = [n for n in names if n in free]
    masses = {n for n, _ in _tangential_dof_names(spec)}
    draws = [set(names)] + [{n for n in names if rng.random() < 0.5} for _ in range(3)] if names else [set()]
    for subset in draws:
        values = {n: (math.inf if n in subset else float(10 ** rng.uniform(5, 10))) for n in names}
        if subset & masses:
            with pytest.raises(ParameterError, match="tangential DOF"):
                space.resolve(values)
            assert evaluate_point(space, values).status == PointStatus.INVALID
            continue
        _check_verdict(space.resolve(values))
        pv = evaluate_point(space, values)
        assert pv.status in (PointStatus.OK, PointStatus.OK_NONTRIVIAL, PointStatus.UNDECIDED)
        if pv.decided:
            assert math.isfinite(pv.max_real) and pv.stable == (pv.max_real < 0)
