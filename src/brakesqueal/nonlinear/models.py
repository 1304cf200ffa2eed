r"""The brake models as systems of the nonlinear machinery: Hopf criticality at every stability crossing.

:func:`model_system` turns any model (the paper's, the built-in and TOML
models) and one settable parameter of a
:class:`~brakesqueal.model.parameters.ParameterSpace` into a
:class:`~.system.SmoothSystem`: the state is the integrator's
``y = (Q, Qdot, L_dynamic)`` in SI units
(:class:`~brakesqueal.simulation.SimulationModel`), ``f`` is the compiled
right-hand side of the simulation and ``A = f_y`` its exact Jacobian from the
generated derivatives of eq. (44) and the pads' balances (implicit
differentiation, :func:`~brakesqueal.simulation.state_jacobian`).  The second
and third derivatives ``B``, ``C`` of Kuznetsov's formula are central
differences of that exact Jacobian with error estimates
(:func:`~.system.fd_bilinear`, :func:`~.system.fd_trilinear`), so ``l1``
carries an error bar.

:func:`hopf_points` finds the stability crossings along a path
(:func:`~brakesqueal.analysis.crossings.crossings`, exact where the model
allows) and computes at each the first Lyapunov coefficient with MatCont's
conventions (:func:`~.hopf.first_lyapunov`): ``<q, q> = 1``, ``<p, q> = 1``,
``l1 = Re c1 / omega0``, and the normalisation-free prediction of every state
component's first-harmonic amplitude ``A_j ~ a_j sqrt(|p - p0|)``.

:func:`limit_cycles` continues the cycles from the first Hopf point by the route
:func:`cycle_route` chooses: shooting (:func:`~.squeal.squeal_branch`) or harmonic
balance (:func:`~.harmonic.harmonic_branch`).  Every function takes the model's
engine first (built by the caller: :mod:`brakesqueal.api_nonlinear`).

Pad treatment (stated in every result): massless pads with Coulomb friction
are quasi-static (``ldot := 0``) here as in the simulation; this is exact for
the linearization at the trivial silent motion but not beyond first order
(with a finite ``k_ip`` the pads' true tangential rate changes ``l1``).  Rigid
pads (``k_ip = inf``), pads with their own tangential DOF and pads with
rate-dependent friction have no such approximation.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from ..errors import BrakesquealError
from .hopf import HopfResult, first_lyapunov
from .system import PiecewiseSystem, SmoothSystem, Transition

if TYPE_CHECKING:
    from ..analysis.maps import Axis
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace
    from ..results import CrossingResult

__all__ = ["model_system", "model_piecewise_system", "hopf_points", "HopfPoint", "PAD_TREATMENTS",
           "soft_quasi_static_pads", "cycle_route", "cycle_space", "limit_cycles"]

#: Pad treatments a limit-cycle computation can be asked for (:func:`cycle_route`).
PAD_TREATMENTS: tuple[str, ...] = ("auto", "exact", "quasi-static")


_K = TypeVar("_K")
_V = TypeVar("_V")


def _recent(compute: Callable[[_K], _V], keep: int = 8) -> Callable[[_K], _V]:
    """``compute(key)`` memoized; the memo is emptied before a new value when it holds more than ``keep``."""
    memo: dict[_K, _V] = {}

    def get(key: _K) -> _V:
        if key not in memo:
            if len(memo) > keep:
                memo.clear()
            memo[key] = compute(key)
        return memo[key]

    return get


def model_system(engine: Engine, space: ParameterSpace, name: str, *, use_cache: bool = True) -> SmoothSystem:
    """A model as a :class:`~.system.SmoothSystem` in the settable parameter ``name`` of ``space``.

    Parameters
    ----------
    engine : Engine
        The model's engine (built by the caller, e.g. :func:`brakesqueal.engine`).
    space : ParameterSpace
        The model, preset and overrides; tied names follow ``name``.
    name : str
        The continuation parameter (a settable name of ``space``, e.g. ``Omega`` or ``mu``).
    use_cache : bool
        Use the on-disk code cache.

    Returns
    -------
    SmoothSystem
        ``f(y, p)``, exact ``jac(y, p)``; state names ``Q``, ``dQ``, dynamic pads' ``L``.

    Raises
    ------
    ParameterError
        ``name`` is not settable in ``space``, or ``space`` is not of the engine's model.
    """
    from ..simulation import simulation_model

    if name not in space.settable():
        space.resolve({name: 1.0})  # raises the one message for unknown or tied names
    sim = simulation_model(engine, use_cache=use_cache)
    sim.parameters(space.resolve({}))  # the space is of the engine's model

    def fields_at(p: float) -> tuple[Any, Any]:
        return sim.vector_field(space.resolve({name: p}))

    fields = _recent(fields_at)

    def f(x: np.ndarray, p: float) -> np.ndarray:
        return fields(float(p))[0](x)

    def jac(x: np.ndarray, p: float) -> np.ndarray:
        return fields(float(p))[1](x)

    system = SmoothSystem(f=f, jac=jac, n=len(sim.state_names), state_names=tuple(sim.state_names),
                          parameter_name=name)
    object.__setattr__(system, "simulation_model", sim)
    # shooting and continuation integrate with the compiled flow and the generated exact Jacobian
    from .compiled import model_flow

    object.__setattr__(system, "default_flow",
                       lambda: model_flow(engine, space, name, system=system, use_cache=use_cache))
    return system


def model_piecewise_system(engine: Engine, space: ParameterSpace, name: str, *,
                           use_cache: bool = True) -> PiecewiseSystem:
    """A model with unilateral contact as a :class:`~.system.PiecewiseSystem` in the parameter ``name``.

    Mode ``m`` (a bit mask: bit ``j`` set when pad ``j`` is lifted off; mode 0
    is every pad pressed, the smooth system of :func:`model_system`) has the
    vector field of the simulation with ``contact="unilateral"``
    (:meth:`SimulationModel.vector_field <brakesqueal.simulation.SimulationModel.vector_field>`
    with ``engaged``): a lifted pad exerts no force.  A pressed pad lifts off
    when its ``F_n`` (the bilateral normal force) falls through 0, a lifted
    pad comes back when it rises through 0.  The vector field is continuous
    across these surfaces (the force is 0 there), so the saltation matrices
    are the identity and no reset is applied.

    Parameters
    ----------
    engine : Engine
        The model's engine (built by the caller).
    space : ParameterSpace
        The model, preset and overrides (pads with coulomb friction, with
        their own degrees of freedom, or with a tangential damper ``d_ip``;
        rate-dependent friction without a damper is refused).
    name : str
        The continuation parameter.
    use_cache : bool
        Use the on-disk code cache.

    Returns
    -------
    PiecewiseSystem
        ``2**n_pads`` modes named by their lifted pads (``"pressed"``,
        ``"lifted 1"``, ``"lifted 1,2"``, ...).

    Raises
    ------
    ParameterError
        ``name`` not settable, or a pad with rate-dependent friction and no damper.
    """
    from ..errors import ParameterError

    smooth = model_system(engine, space, name, use_cache=use_cache)
    sim = smooth.simulation_model  # type: ignore[attr-defined]
    if undamped := sim.undamped(space.resolve({})):
        raise ParameterError(f"unilateral contact needs a tangential damper d_ip > 0 on every pad whose rate is a "
                             f"state ({', '.join(undamped)}, rate-dependent friction): without one the pad's rate is "
                             "not determined down to lift-off (docs/simulation.md, unilateral contact)")
    pads = sim.pads
    npad = len(pads)

    def state_at(p: float) -> tuple[Any, Any]:
        params = space.resolve({name: p})
        return params, sim.silent(params)

    def fields_at(key: tuple[float, int]) -> Any:
        p, mode = key
        params, st = state(p)
        return sim.vector_field(params, st, engaged=[not (mode >> j) & 1 for j in range(npad)])

    states = _recent(state_at)
    mode_fields = _recent(fields_at, 8 * 2**npad)

    def state(p: float) -> tuple[Any, Any]:
        return states(float(p))

    def fields(p: float, mode: int) -> Any:
        return mode_fields((float(p), mode))

    def normal_force(j: int, mode: int) -> Any:
        # the bilateral normal force of pad j with the pads' rates of `mode` (a lifted pad with a damper relaxes)
        engaged = [not (mode >> i) & 1 for i in range(npad)]

        def h(x: np.ndarray, p: float) -> float:
            params, st = state(p)
            return float(sim.contact_at(params, x, st, engaged=engaged)[j, 0])

        return h

    def mode_of(x: np.ndarray, p: float) -> int:
        params, st = state(p)
        try:
            F = sim.contact_at(params, x, st)[:, 0]
        except ParameterError:  # a damped pad's rate at a state where it would pull: solve it as lifted
            F = sim.contact_at(params, x, st, engaged=[False] * npad)[:, 0]
        return int(sum(1 << j for j in range(npad) if not F[j] > 0))

    modes, transitions, names = [], [], []
    for m in range(2 ** npad):
        if m == 0:
            modes.append(smooth)
        else:
            def f(x: np.ndarray, p: float, _m: int = m) -> np.ndarray:
                return fields(p, _m)[0](x)

            def jac(x: np.ndarray, p: float, _m: int = m) -> np.ndarray:
                return fields(p, _m)[1](x)

            modes.append(SmoothSystem(f=f, jac=jac, n=smooth.n, state_names=smooth.state_names,
                                      parameter_name=name))
        tr = []
        for j in range(npad):
            if (m >> j) & 1:
                tr.append(Transition(normal_force(j, m), m & ~(1 << j), +1, name=f"re-contact-pad-{pads[j]}"))
            else:
                tr.append(Transition(normal_force(j, m), m | (1 << j), -1, name=f"contact-loss-pad-{pads[j]}"))
        transitions.append(tuple(tr))
        lifted = [pads[j] for j in range(npad) if (m >> j) & 1]
        names.append("lifted " + ",".join(lifted) if lifted else "pressed")
    pw = PiecewiseSystem(tuple(modes), tuple(transitions), mode_of, tuple(names))
    object.__setattr__(pw, "simulation_model", sim)
    return pw


@dataclass(frozen=True)
class HopfPoint:
    """A stability crossing of the silent motion with its Hopf normal-form data.

    Attributes
    ----------
    parameter : str
        The path parameter.
    value : float
        Where stability changes (refined Hopf point when ``hopf`` is given).
    direction : str
        ``"destabilizing"`` or ``"stabilizing"`` with increasing parameter.
    hopf : HopfResult or None
        The normal form of the model's equations with the pads' true tangential dynamics
        (:func:`~.implicit.exact_lyapunov`; ``None`` when it could not be computed, see ``message``).
    pad_treatment : dict
        Every pad deformation's treatment in the *simulated* equations (``"quasi-static"`` or
        ``"dynamic"``): those of :attr:`simulated`, of the simulation and of limit-cycle branches.
    message : str
        Why ``hopf`` is missing, or a note on the pad treatment.
    simulated : HopfResult or None
        The normal form of the simulated equations (:func:`model_system`) when they differ from the
        exact ones (massless Coulomb pads with a finite ``k_ip`` are quasi-static there): the start of
        limit-cycle branches.  ``None`` when the simulated equations are exact.
    contact_loss, sliding_reversal : float or None
        Leading-order predictions from ``hopf`` of where a pad first lifts off and where a pad's
        sliding velocity (its rate included) first reverses on the cycle (the end of the model's
        validity); ``None`` when not predicted.
    tilt_at_contact_loss, tilt_at_sliding_reversal : float or None
        The predicted largest tilt amplitude [rad] there.
    """

    parameter: str
    value: float
    direction: str
    hopf: HopfResult | None
    pad_treatment: dict[str, str]
    message: str = ""
    simulated: HopfResult | None = None
    contact_loss: float | None = None
    sliding_reversal: float | None = None
    tilt_at_contact_loss: float | None = None
    tilt_at_sliding_reversal: float | None = None

    @property
    def branch_start(self) -> HopfResult | None:
        """The normal form in the simulated equations' state (where limit-cycle branches start)."""
        return self.simulated if self.simulated is not None else self.hopf

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary: l1 and its error, criticality, frequency, side and amplitude coefficients."""
        d: dict[str, Any] = {"value": self.value, "direction": self.direction, "pad_treatment": self.pad_treatment,
                             "message": self.message}
        h = self.hopf
        if h is None:
            d["hopf"] = None
            return d
        d["hopf"] = _hopf_dict(h)
        d["hopf"]["pad_dynamics"] = "exact (tangential rates kept; centre manifold of the implicit equations)"
        d["predicted"] = {"contact_loss": self.contact_loss, "sliding_reversal": self.sliding_reversal,
                          "tilt_at_contact_loss": self.tilt_at_contact_loss,
                          "tilt_at_sliding_reversal": self.tilt_at_sliding_reversal}
        d["hopf_simulated"] = None if self.simulated is None else _hopf_dict(self.simulated)
        return d


def soft_quasi_static_pads(space: ParameterSpace, axis: Axis | None = None) -> tuple[str, ...]:
    """Pads whose tangential rate the simulation drops (``ldot := 0``) although their ``k_ip`` is finite.

    These are the massless pads with Coulomb friction, no tangential damper and a finite ``k_ip``
    (anywhere on ``axis`` when ``k_ip`` is its parameter): for them the simulated equations, and the
    limit-cycle branches shot from them, are exact only to first order at the onset (``docs/nonlinear.md``).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    axis : Axis, optional
        A path; its two ends are checked as well as the preset's values.

    Returns
    -------
    tuple of str
        Pad names, in the model's order (empty when the simulated equations are exact).
    """
    from ..simulation.trajectory import soft_quasi_static_pads as soft_at

    params = space.resolve({})
    where = [params] + ([space.resolve({axis.name: float(v)}) for v in (axis.start, axis.stop)]
                        if axis is not None else [])
    soft = {pad for pv in where for pad in soft_at(pv)}
    return tuple(p.name for p in params.model.pads if p.name in soft)


def cycle_route(space: ParameterSpace, axis: Axis | None = None, *, contact: str = "bilateral",
                pads: str = "auto") -> str:
    """The route that computes limit cycles of a model with the pads' true tangential dynamics.

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides (after any pad option such as
        :func:`~brakesqueal.model.options.damped_pads`).
    axis : Axis, optional
        The continuation path (its ends decide for a path in ``k_ip``).
    contact : {"bilateral", "unilateral"}
        As in :func:`~.squeal.squeal_branch`.
    pads : {"auto", "exact", "quasi-static"}
        ``"auto"``: shooting (:func:`~.squeal.squeal_branch`) wherever the simulated equations keep every pad's rate
        (rigid pads, pads with mass, rate-dependent laws, tangential dampers); harmonic balance on the implicit
        equations (:func:`~.harmonic.harmonic_branch`, the massless Coulomb pads exact) where soft Coulomb pads
        would be quasi-static (:func:`soft_quasi_static_pads`).  ``"exact"``: harmonic balance.
        ``"quasi-static"``: shooting with ``ldot := 0`` for those pads (exact to first order at the onset).

    Returns
    -------
    str
        ``"shooting"`` or ``"harmonic balance"``.

    Raises
    ------
    ParameterError
        A bad ``pads`` or ``contact``; harmonic balance with ``contact="unilateral"`` (it is bilateral, to the
        located contact loss); and ``"auto"`` with unilateral contact and soft massless Coulomb pads: their rate
        has no defined value through lift-off (the rate balance folds before ``F_n = 0``), so the treatment is
        the user's choice, named in the message.
    """
    from ..errors import ParameterError

    if pads not in PAD_TREATMENTS:
        raise ParameterError(f"The option 'pads' must be one of {', '.join(PAD_TREATMENTS)}; got {pads!r}",
                             parameter="pads")
    if contact not in ("bilateral", "unilateral"):
        raise ParameterError(f"The option 'contact' must be bilateral or unilateral; got {contact!r}",
                             parameter="contact")
    if pads == "quasi-static":
        return "shooting"
    if pads == "exact":
        if contact != "bilateral":
            raise ParameterError("The option 'pads' = exact (harmonic balance; --pads exact or --exact-pads) is "
                                 "bilateral, to the located contact loss; through lift-off keep the pads' rates with "
                                 "a tangential damper (--pad-damping D) or choose --pads quasi-static",
                                 parameter="pads")
        return "harmonic balance"
    soft = soft_quasi_static_pads(space, axis)
    if not soft:
        return "shooting"
    if contact == "bilateral":
        return "harmonic balance"
    raise ParameterError(
        f"unilateral contact needs a choice for the massless Coulomb pads {', '.join(soft)} (finite k_ip): their "
        "tangential rate has no defined value through lift-off (the rate balance folds before F_n = 0). Choose "
        "--pad-damping D (the rates kept, a damper beside each pad; converges as D -> 0, e.g. 10 N s/m) or "
        "--pads quasi-static (ldot := 0, exact to first order at the onset)", parameter="pads")


def cycle_space(space: ParameterSpace, *, pads: str = "auto", pad_slope: float | None = None,
                stick_speed: float | None = None) -> ParameterSpace:
    """The parameter space a limit-cycle computation runs on: ``space``, or with ``pad_slope`` its massless
    Coulomb pads regularised (:func:`~brakesqueal.model.options.regularised_pads`: a rising law that keeps the
    pads' rates, error O(pad_slope); with ``stick_speed`` the law ``stick``).

    A regularised space is another model: its engine is built by the caller from the returned space
    (:func:`brakesqueal.limit_cycles` and :func:`brakesqueal.squeal_branch` do both).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    pads : {"auto", "exact", "quasi-static"}
        The requested pad treatment (:func:`cycle_route`): ``pad_slope`` needs ``"auto"``.
    pad_slope, stick_speed : float, optional
        As for :func:`~brakesqueal.model.options.regularised_pads`.

    Returns
    -------
    ParameterSpace

    Raises
    ------
    ParameterError
        ``pad_slope`` with ``pads`` other than ``"auto"``, ``stick_speed`` without ``pad_slope``, or a value
        out of range (naming the option).
    """
    from ..errors import ParameterError

    if pad_slope is None and stick_speed is None:
        return space
    if pads != "auto":
        raise ParameterError(f"The option 'pad_slope' (a rising law that keeps the pads' rates, shooting) "
                             f"cannot be combined with pads = {pads!r}", parameter="pads")
    if pad_slope is None:
        raise ParameterError("stick_speed regularises the pads of pad_slope; give pad_slope too",
                             parameter="stick_speed")
    from ..model.options import regularised_pads

    return regularised_pads(space, pad_slope, stick_speed)


#: Options of :func:`limit_cycles` each route takes (beyond ``max_points`` and ``progress``).
_ROUTE_OPTIONS: dict[str, frozenset[str]] = {
    "shooting": frozenset({"use_cache", "tol", "ds", "ds_max", "flow_method"}),
    "harmonic balance": frozenset({"use_cache", "tol", "ds", "ds_max", "harmonics", "max_harmonics",
                                   "harmonic_tol", "start_offset", "stability", "stop_at_contact_loss",
                                   "residual_tol", "mismatch_tol", "shooting_check"}),
}


def limit_cycles(engine: Engine, space: ParameterSpace, axis: Axis, *, contact: str = "bilateral", pads: str = "auto",
                 max_points: int | None = None, progress: Callable[[float], None] | None = None,
                 **options: Any) -> Any:
    """Limit cycles from the first Hopf point on a path, by the route ``brakesqueal cycles`` takes.

    The library's counterpart of the command: the pads' true tangential dynamics by default
    (:func:`cycle_route`), so a call needs no knowledge of which route keeps them.

    Parameters
    ----------
    engine : Engine
        The engine of ``space``'s model (built by the caller; :func:`brakesqueal.limit_cycles` builds it).
    space : ParameterSpace
        The model, preset and overrides (after any pad option such as
        :func:`~brakesqueal.model.options.damped_pads` or :func:`cycle_space`).
    axis : Axis
        The path: the first Hopf point with a cycle prediction in it is continued within it.
    contact : {"bilateral", "unilateral"}
        As in :func:`~.squeal.squeal_branch` (unilateral: shooting only).
    pads : {"auto", "exact", "quasi-static"}
        As in :func:`cycle_route`.
    max_points : int, optional
        Largest number of branch points (default: the route's own, 60 for shooting, 40 for harmonic
        balance).
    progress : callable, optional
        ``progress(fraction)`` after each branch point (see :func:`~.squeal.squeal_branch`); what it raises stops
        the branch and propagates.
    **options
        Options of the route taken: shooting (:func:`~.squeal.squeal_branch`): ``use_cache``, ``tol``, ``ds``,
        ``ds_max``, ``flow_method``; harmonic balance
        (:func:`~.harmonic.harmonic_branch`): ``use_cache``, ``tol``, ``ds``, ``ds_max``, ``harmonics``,
        ``max_harmonics``, ``harmonic_tol``, ``start_offset``, ``stability``, ``stop_at_contact_loss``,
        ``residual_tol``, ``mismatch_tol``, ``shooting_check``.

    Returns
    -------
    SquealBranch or HarmonicBranch
        The shooting branch or the harmonic-balance branch; both carry ``summary`` (a
        :class:`~.squeal.SquealSummary`), ``contact_loss``, ``plot()`` and ``to_dict()`` (whose ``route`` names the
        route).

    Raises
    ------
    ParameterError
        A bad ``contact`` or ``pads``, a combination :func:`cycle_route` refuses, an option the route taken
        does not have (naming it and the route), or any error of the route's own validation.
    """
    from ..errors import ParameterError

    for opt in ("pad_slope", "stick_speed"):
        if opt in options:
            raise ParameterError(f"The option {opt!r} changes the model: regularise the space with cycle_space() and "
                                 "pass the engine of its model (brakesqueal.limit_cycles does both)", parameter=opt)
    route = cycle_route(space, axis, contact=contact, pads=pads)
    bad = sorted(set(options) - _ROUTE_OPTIONS[route])
    if bad:
        other = "harmonic balance" if route == "shooting" else "shooting"
        raise ParameterError(f"The option {bad[0]!r} does not apply to the {route} route this model and path "
                             f"take (pads = {pads!r}); it is an option of "
                             + (f"the {other} route" if bad[0] in _ROUTE_OPTIONS[other] else "neither route"),
                             parameter=bad[0])
    kw = dict(options)
    if max_points is not None:
        kw["max_points"] = max_points
    if route == "harmonic balance":
        from .harmonic import harmonic_branch

        return harmonic_branch(engine, space, axis, progress=progress, **kw)
    from .periodic import ShootingError
    from .squeal import squeal_branch

    try:
        return squeal_branch(engine, space, axis, contact=contact, progress=progress, **kw)
    except ShootingError as exc:
        # The default route must not refuse a branch that the other route computes: where the shooting cannot
        # start (Newton's method does not converge to the first orbit) and the pads allow harmonic balance with
        # their exact rates (bilateral contact, only options that route has), the branch comes from it, saying so.
        if pads != "auto" or contact != "bilateral" or set(kw) - _ROUTE_OPTIONS["harmonic balance"] - {"max_points"}:
            raise
        import dataclasses

        from .harmonic import harmonic_branch

        from ..errors import BrakesquealError

        try:
            hb = harmonic_branch(engine, space, axis, progress=progress, **kw)
        except BrakesquealError as exc2:
            raise ShootingError(f"{exc}; harmonic balance with the exact pads did not compute the branch either: "
                                f"{exc2}") from None
        return dataclasses.replace(hb, message=f"shooting did not converge ({exc}); harmonic balance with the "
                                               f"exact pads instead: {hb.message}")


def _hopf_dict(h: HopfResult) -> dict[str, Any]:
    names = tuple(h.state_names or ())
    return {
        "p0": h.p0, "omega0": h.omega0, "frequency_hz": h.frequency0_hz, "l1": h.l1,
        "l1_error": h.l1_error, "criticality": h.criticality, "c1": [h.c1.real, h.c1.imag],
        "dRe_lambda_dp": h.dRe_lambda_dp, "side": h.side,
        "cycles_exist_for": ("p > p0" if h.side > 0 else "p < p0") if h.side else None,
        "amplitude_coefficients": dict(zip(names, map(float, h.amplitude_coefficients))),
        "frequency_slope": h.frequency_slope, "multilinear": h.multilinear,
        "conventions": "state (" + ", ".join(names) + ") in SI units; <q,q> = 1, <p,q> = 1; l1 = Re(c1)/omega0 "
                       "(Kuznetsov; MatCont); A_j ~ a_j sqrt(|p - p0|)",
        "warnings": list(h.warnings),
    }


def hopf_points(engine: Engine, space: ParameterSpace, axis: Axis, *, use_cache: bool = True,
                result: CrossingResult | None = None) -> list[HopfPoint]:
    """Every stability crossing along a path with its first Lyapunov coefficient and cycle prediction.

    Parameters
    ----------
    engine : Engine
        The model's engine (built by the caller).
    space : ParameterSpace
        The model, preset and overrides (any model).
    axis : Axis
        The path (``name``, ``start``, ``stop``; ``log`` as for
        :func:`~brakesqueal.analysis.crossings.crossings`).
    use_cache : bool
        Use the on-disk code cache.
    result : CrossingResult, optional
        The crossings along ``axis`` when already computed (default: computed here).

    Returns
    -------
    list of HopfPoint
        In increasing parameter order; ``hopf`` with the pads' true tangential dynamics
        (:func:`~.implicit.exact_lyapunov`), ``simulated`` for the simulated equations when they
        differ.  A crossing where the normal form cannot be computed (a real eigenvalue crossing,
        a failed refinement) has ``hopf = None`` and a message.
    """
    from ..analysis.crossings import crossings
    from ..simulation.trajectory import soft_quasi_static_pads as soft_at
    from .implicit import exact_lyapunov

    system = model_system(engine, space, axis.name, use_cache=use_cache)
    sim = system.simulation_model  # type: ignore[attr-defined]
    r = crossings(engine, space, axis) if result is None else result
    treatment = dict(zip(sim.pad_unknowns, sim.pad_kinds))
    out = []
    for value, direction in r.crossings:  # type: ignore[attr-defined]
        try:
            ex = exact_lyapunov(engine, space, axis.name, float(value), use_cache=use_cache)
        except (BrakesquealError, np.linalg.LinAlgError) as exc:
            out.append(HopfPoint(axis.name, float(value), direction, None, treatment,
                                 f"no Hopf normal form: {exc}"))
            continue
        h = ex.hopf
        simulated, note = None, ""
        soft = bool(soft_at(space.resolve({axis.name: h.p0})))
        if soft or tuple(h.state_names) != tuple(system.state_names or ()):
            # the simulated equations' own normal form (their state; with soft pads also their approximation)
            try:
                y0 = sim.silent(space.resolve({axis.name: h.p0})).y
                simulated = first_lyapunov(system, y0, h.p0, refine=True, omega=h.omega0)
                if soft:
                    note = (f"the simulation and limit-cycle branches use quasi-static pads (ldot := 0; exact only "
                            f"to first order): l1 = {simulated.l1:.6g} ({simulated.criticality}) there; the pads' "
                            "rates are kept by cycles (default --pads auto: harmonic balance, bilateral), "
                            "--pad-damping D (through lift-off; a damper d_ip) or --pad-slope S")
            except (BrakesquealError, np.linalg.LinAlgError) as exc:
                note = f"no normal form of the simulated equations: {exc}"
            if simulated is not None and simulated.criticality != h.criticality:
                note = (note + "; " if note else "") + (
                    f"the criticality of the simulated equations ({simulated.criticality}) differs from the exact "
                    f"{h.criticality}: the simulated branch does not describe the brake near onset")
        out.append(HopfPoint(axis.name, float(h.p0), direction, h, treatment, note, simulated,
                             ex.contact_loss, ex.sliding_reversal, ex.tilt_at_contact_loss,
                             ex.tilt_at_sliding_reversal))
    return out
