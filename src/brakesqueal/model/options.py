"""One resolution of ``--model``, ``--preset``, ``--params`` and ``--set`` for every command and the API."""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from ..inputs import check_option
from ..validation import validated
from ..errors import ParameterError
from .parameters import ParameterSpace, Parameters, Value, parse_sets

if TYPE_CHECKING:
    from .components import ModelSpec
    from .matrices import MatrixSpec

__all__ = ["resolve_space", "resolve_parameters", "regularised_pads", "damped_pads", "stick_slip_everywhere",
           "DEFAULT_PRESET", "MAX_PAD_SLOPE", "MAX_STICK_SPEED", "MAX_PAD_DAMPING"]

#: The preset used when neither a model, a preset nor a parameter file is given.
DEFAULT_PRESET = "paper-fig2"


@validated
def resolve_space(model: ModelSpec | MatrixSpec | str | os.PathLike[str] | None = None, preset: str | None = None,
                  params: str | os.PathLike[str] | None = None,
                  sets: Sequence[str] | Mapping[str, Any] = ()) -> ParameterSpace:
    """Combine the model, preset, parameter-file and ``--set`` options into one parameter space.

    Parameters
    ----------
    model : ModelSpec, MatrixSpec, str or os.PathLike, optional
        A model, a built-in model name or a model file path (``--model``).
    preset : str, optional
        A preset name (``--preset``): a preset of the model, or, without a
        model, any built-in preset (which names its model).  Never empty.
    params : str or os.PathLike, optional
        A parameter file (``--params``): optional ``model`` and ``preset``
        keys and a ``[parameters]`` table of overrides.
    sets : sequence of str or dict, optional
        ``NAME=VALUE`` assignments (``--set``) or a ready ``{name: value}``
        dict; they override the file.  Setting a tied name replaces its tie
        (see :attr:`ParameterSpace.untied`).

    Returns
    -------
    ParameterSpace
        Validated (its current point resolves).

    Notes
    -----
    Without a preset the model's default preset is used (every parameter
    free at the model's default value); with nothing at all, the preset
    :data:`DEFAULT_PRESET`.  A parameter file without ``model`` and
    ``preset`` keys must give every parameter of the paper's model (as in
    earlier versions).

    Raises
    ------
    ParameterError
        Arguments of the wrong type, an empty or too long option
        (:func:`brakesqueal.inputs.check_option`), conflicting model or
        preset names between the options and the file, unknown names (with a
        suggestion), invalid values.
    """
    from .components import ModelSpec
    from .library import get_model, get_preset, resolve_model

    if isinstance(model, (str, os.PathLike)):
        model = check_option(model, "--model")
    preset = check_option(preset, "--preset", name=True)
    params = check_option(params, "--params")
    overrides = dict(sets) if isinstance(sets, Mapping) else parse_sets(list(sets))
    entries: dict[str, Value] = {}
    f_model = f_preset = None
    source = None
    if params is not None:
        from .io import load_parameter_file

        f_model, f_preset, entries = load_parameter_file(params)
        source = f"parameter file '{params}'"
    from .matrices import MatrixSpec

    spec = (model if isinstance(model, (ModelSpec, MatrixSpec)) else
            (resolve_model(model) if model is not None else None))
    if f_model is not None:
        f_spec = resolve_model(f_model)
        if spec is not None and spec.name != f_spec.name:
            raise ParameterError(f"{source}: key 'model' = '{f_spec.name}' conflicts with --model '{spec.name}'")
        spec = spec or f_spec
    if preset is not None and f_preset is not None and preset != f_preset:
        raise ParameterError(f"{source}: key 'preset' = '{f_preset}' conflicts with --preset '{preset}'")
    name = preset or f_preset
    try:
        if name is not None:
            pr = spec.get_preset(name) if spec is not None else get_preset(name)
        elif spec is not None:
            pr = spec.get_preset(None)
        elif params is not None:
            # a complete parameter set of the paper's model
            p = Parameters(get_model("paper"), {**entries, **overrides}, source=source)
            return ParameterSpace.from_parameters(p)
        else:
            pr = get_preset(DEFAULT_PRESET)
        space = ParameterSpace(pr, {**entries, **overrides})
        space.resolve({})
    except ParameterError as exc:
        if source is None or str(exc).startswith(source):
            raise
        raise ParameterError(f"{source}: {exc}") from None
    return space


@validated
def resolve_parameters(model: ModelSpec | MatrixSpec | str | os.PathLike[str] | None = None,
                       preset: str | None = None, params: str | os.PathLike[str] | None = None,
                       sets: Sequence[str] | Mapping[str, Any] = ()) -> Parameters:
    """The validated parameter set of :func:`resolve_space` at its current point.

    Parameters
    ----------
    model, preset, params, sets
        As for :func:`resolve_space`.

    Returns
    -------
    Parameters
    """
    return resolve_space(model, preset, params, sets).resolve({})


#: Largest pad slope accepted by :func:`regularised_pads` [s/m] (it changes ``l1`` by O(slope)).
MAX_PAD_SLOPE = 1e-2
#: Largest stick-slip regularisation speed accepted by :func:`regularised_pads` [m/s].
MAX_STICK_SPEED = 1.0
#: Largest tangential pad damping of :func:`damped_pads` [N s/m].
MAX_PAD_DAMPING = 1e6


def _in_range(option: str, value: float, high: float, unit: str) -> float:
    """``value`` as a float in ``(0, high]``, else a ParameterError naming ``option``."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = math.nan
    if not (0 < x <= high):
        raise ParameterError(f"The option '{option}' must be in (0, {high:g}] {unit}; got {value!r}",
                             parameter=option)
    return x


def stick_slip_everywhere(spec: ModelSpec) -> bool:
    """Whether every pad of ``spec`` has regularised stick-slip (the law ``stick``).

    Only then is a sliding reversal ordinary motion for the simulation (``events="stop"`` stops at contact
    loss only) and for limit-cycle branches (no end of validity); a Coulomb pad anywhere else (rigid, or with
    its own DOF) would stick there.

    Parameters
    ----------
    spec : ModelSpec
        The model.

    Returns
    -------
    bool
    """
    return bool(spec.pads) and all(pad.friction.law == "stick" for pad in spec.pads)


def regularised_pads(space: ParameterSpace, slope: float, stick_speed: float | None = None) -> ParameterSpace:
    """``space`` with the pads' tangential rates made regular: Coulomb friction replaced by ``mu + slope v``.

    Every massless pad with Coulomb friction and a finite tangential stiffness gets the rising law ``mu(v) =
    mu + slope v`` (the law ``linear`` with the field ``slope = -slope``).  Its rate is then a regular state
    of the explicit equations (pad mode ``~ -k_ip / (N0 slope)``), so the simulation and the limit-cycle
    branches keep it; as ``slope -> 0`` their normal form tends to the Coulomb pads' exact one
    (:func:`~brakesqueal.nonlinear.implicit.exact_lyapunov`) at rate O(slope).  The price is also O(slope):
    the friction level at the silent motion rises by ``slope * Omega * r`` (paper's model, ``k_ip = 1e6``,
    ``slope = 1e-4``: the onset moves by 0.6 %, ``l1`` by 2.4 %).  Smaller slopes make the pad mode faster
    (``1e-5`` already defeats the explicit integrator there).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    slope : float
        ``d mu / d v`` [s/m], in ``(0, MAX_PAD_SLOPE]``.
    stick_speed : float, optional
        Also regularise stick-slip: the law ``stick`` (:mod:`~brakesqueal.model.friction`),
        ``mu(v) = mu v / sqrt(v^2 + stick_speed^2) + slope v``, so that the friction force is smooth through
        zero relative velocity and a pad that would stick creeps at a relative speed of order
        ``stick_speed`` [m/s], in ``(0, MAX_STICK_SPEED]``.  Sliding reversals are then ordinary motion
        (``docs/simulation.md``, stick-slip); the error is O(``stick_speed``) besides O(``slope``), and the
        friction level at the silent motion falls by about ``mu stick_speed^2 / (2 (Omega r)^2)``.

    Returns
    -------
    ParameterSpace
        The same preset and overrides on the modified model (named ``<model>+rising-pads``); ``space``
        itself when no pad needs it.

    Raises
    ------
    ParameterError
        ``slope`` or ``stick_speed`` out of range.
    """
    from dataclasses import replace

    from .components import FrictionLaw
    from .friction import LAWS

    value = _in_range("pad_slope", slope, MAX_PAD_SLOPE, "s/m")
    v_reg = None if stick_speed is None else _in_range("stick_speed", stick_speed, MAX_STICK_SPEED, "m/s")
    spec = space.resolve({}).model
    pads, changed = [], False
    for pad in spec.pads:
        if pad.quasi_static and not LAWS[pad.friction.law].rate_dependent:
            law = (FrictionLaw("linear", pad.friction.mu, slope=-value) if v_reg is None
                   else FrictionLaw("stick", pad.friction.mu, v_reg=v_reg, slope=-value))
            pad = replace(pad, friction=law)
            changed = True
        pads.append(pad)
    if not changed:
        return space
    new = replace(spec, name=f"{spec.name}+{'rising-pads' if v_reg is None else 'stick-slip-pads'}", pads=tuple(pads))
    return type(space)(space.preset.bind(new), dict(space.values))


def damped_pads(space: ParameterSpace, d_ip: float) -> ParameterSpace:
    """``space`` with a tangential damper ``d_ip`` beside the spring of every massless pad (not in the paper).

    A massless pad with a finite tangential stiffness then balances ``k_ip (l - u_m) + d_ip (ldot - u_mdot) =
    -(f_t + mu* N0)`` (``brakesqueal.symbolic.contact``): its rate is a state whose balance has the slope
    ``dG/dldot = (d_ip + df_t/dldot) / k_ip``, where ``df_t/dldot`` is the friction's monotone part (>= 0) plus a
    coupling through the normal force of either sign and small size (the support damper acting on the contact
    height: about ``mu d |tilt|``, 0.012 N s/m on paper-fig3 at 5 mrad), so the simulation and the limit-cycle
    branches keep
    the pads' true tangential dynamics through lift-off and re-contact (a lifted pad relaxes with the time
    constant ``d_ip / k_ip``).  Without it the rate of such a pad is not determined near lift-off
    (``docs/simulation.md``, unilateral contact).  The damper changes the model: the linearization gains the
    pads' first-order modes (rate ``~ -k_ip / d_ip``) and the onset moves, less as ``d_ip -> 0``
    (``docs/simulation.md``: paper-fig3 at ``k_ip = 1e6``, 10 N s/m: from 64.81 to 63.84 rad/s).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    d_ip : float
        Tangential damping [N s/m], in ``(0, MAX_PAD_DAMPING]``.

    Returns
    -------
    ParameterSpace
        The same preset and overrides on the modified model (named ``<model>+damped-pads``), whose pads share
        the new parameter ``d_ip`` (``d_ip_pads`` if that name is taken), fixed at ``d_ip`` in every preset and
        settable like any other, so that one compiled model serves every damping; ``space`` itself when no
        pad needs it (pads that are rigid tangentially at ``space``'s values, have their own tangential DOF
        or a damper).

    Raises
    ------
    ParameterError
        ``d_ip`` out of range.
    """
    from dataclasses import replace

    value = _in_range("pad_damping", d_ip, MAX_PAD_DAMPING, "N s/m")
    params = space.resolve({})
    spec = params.model
    taken = set(spec.parameters) | set(space.preset.all_names())
    name = next((n for n in ("d_ip", "d_ip_pads") if n not in taken), None)
    pads, changed = [], False
    for pad in spec.pads:
        massless = "tangential" not in pad.dofs
        finite = math.isfinite(float(params[pad.k_ip]) if isinstance(pad.k_ip, str) else float(pad.k_ip))
        if massless and finite and not pad.tangentially_damped:
            pad = replace(pad, d_ip=name if name else value)
            changed = True
        pads.append(pad)
    if not changed:
        return space
    if name is None:  # both names taken: the value itself (a new compiled model per value)
        new = replace(spec, name=f"{spec.name}+damped-pads", pads=tuple(pads))
        return type(space)(space.preset.bind(new), dict(space.values))
    # a parameter (fixed in every preset): one compiled model serves every damping, settable by --set NAME=...
    presets = tuple(replace(pr, fixed={**pr.fixed, name: value}, model=None) for pr in spec.presets)
    new = replace(spec, name=f"{spec.name}+damped-pads", pads=tuple(pads), parameters={**spec.parameters, name: value},
                  presets=presets)
    preset = replace(space.preset, fixed={**space.preset.fixed, name: value}, model=None).bind(new)
    return type(space)(preset, dict(space.values))
