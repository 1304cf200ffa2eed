r"""The public API of the simulation and the nonlinear analysis: entry points that build the model's engine.

Each function here builds the model's :class:`~brakesqueal.codegen.engine.Engine`
once (:func:`brakesqueal.codegen.build`, memoized per process by the model's
equations) from its parameters or parameter space and hands it down to
:mod:`brakesqueal.simulation` or :mod:`brakesqueal.nonlinear`, which never build
one themselves.  Re-exported by :mod:`brakesqueal` (``brakesqueal.simulate``,
``brakesqueal.limit_cycles``, ...).  ``docs/simulation.md``, ``docs/nonlinear.md``.  Every function checks its
arguments against its type hints first (:func:`brakesqueal.validation.validated`).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Annotated, Any, cast

from .validation import Range, validated

if TYPE_CHECKING:
    import numpy as np

    from .analysis.maps import Axis
    from .codegen.engine import Engine
    from .model.components import ModelSpec
    from .model.matrices import MatrixSpec
    from .model.parameters import Parameters, ParameterSpace
    from .nonlinear.compiled import CompiledFlow
    from .nonlinear.harmonic import HarmonicBranch
    from .nonlinear.implicit import PadHopf
    from .nonlinear.models import HopfPoint
    from .nonlinear.squeal import SquealBranch
    from .nonlinear.system import PiecewiseSystem, SmoothSystem
    from .region import HopfCurve, RegionResult
    from .results import CrossingResult
    from .simulation import SimulationModel, Trajectory

__all__ = ["simulate", "simulation_model", "hopf_points", "limit_cycles", "squeal_branch", "harmonic_branch",
           "model_system", "model_piecewise_system", "exact_lyapunov", "model_flow", "hopf_curves", "region_diagram"]


def _engine(model: ModelSpec | MatrixSpec | str | os.PathLike[str] | Parameters | ParameterSpace,
            use_cache: bool = True) -> Engine:
    from .codegen import build

    from .model.parameters import Parameters, ParameterSpace

    spec = model.model if isinstance(model, (Parameters, ParameterSpace)) else model
    spec = os.fspath(spec) if isinstance(spec, os.PathLike) else spec
    return build(cast("ModelSpec", spec), use_cache=use_cache).require_nonlinear("nonlinear analysis")


@validated
def simulate(params: Parameters, t_span: float | tuple[float, float] = 0.5,
             x0: Sequence[float] | np.ndarray | None = None, *, use_cache: bool = True,
             **options: Any) -> Trajectory:
    """Integrate the nonlinear equations of the model of ``params`` (:func:`brakesqueal.simulation.simulate`).

    Parameters
    ----------
    params : Parameters
        The model and its parameter values.
    t_span : float or (float, float), optional
        End time [s] (start 0) or ``(t0, t_end)``: finite numbers (the simulation checks their order).
    x0 : array_like, optional
        Absolute initial state ``(Q, Qdot[, L_dynamic])``.
    use_cache : bool, optional
        Use the on-disk code cache.
    **options
        The options of :func:`brakesqueal.simulation.simulate` (``perturbation``, ``method``, ``rtol``,
        ``atol``, ``sample_rate``, ``events``, ``contact``, ...).

    Returns
    -------
    Trajectory
    """
    from .analysis.equilibrium import as_parameters
    from .simulation import simulate as _simulate
    from .simulation import simulation_model as _simulation_model

    params = as_parameters(params)
    sim = _simulation_model(_engine(params, use_cache), use_cache=use_cache)
    return _simulate(sim, params, t_span, x0, **options)


@validated
def simulation_model(model: ModelSpec | MatrixSpec | str | os.PathLike[str] | Parameters | ParameterSpace, *,
                     use_cache: bool = True) -> SimulationModel:
    """The simulation model of a model (a :class:`~brakesqueal.model.components.ModelSpec`, a built-in model's
    name, a model file, parameters or a parameter space): :func:`brakesqueal.simulation.simulation_model` of
    its engine.

    Parameters
    ----------
    model : ModelSpec, MatrixSpec, str, os.PathLike, Parameters or ParameterSpace
        The model (a model given by coefficient matrices is refused: it has no nonlinear equations).
    use_cache : bool, optional
        Use the on-disk code cache.

    Returns
    -------
    SimulationModel
    """
    from .simulation import simulation_model as _simulation_model

    return _simulation_model(_engine(model, use_cache), use_cache=use_cache)


@validated
def hopf_points(space: ParameterSpace, axis: Axis, *, use_cache: bool = True,
                result: CrossingResult | None = None) -> list[HopfPoint]:
    """Every stability crossing along a path with its Hopf normal form
    (:func:`brakesqueal.nonlinear.models.hopf_points`).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    axis : Axis
        The path.
    use_cache : bool, optional
        Use the on-disk code cache.
    result : CrossingResult, optional
        The crossings along ``axis`` when already computed.

    Returns
    -------
    list of HopfPoint
    """
    from .nonlinear.models import hopf_points as _hopf_points

    return _hopf_points(_engine(space, use_cache), space, axis, use_cache=use_cache, result=result)


@validated
def limit_cycles(space: ParameterSpace, axis: Axis, *, contact: str = "bilateral", pads: str = "auto",
                 max_points: Annotated[int, Range(1)] | None = None, progress: Callable[[float], None] | None = None,
                 pad_slope: float | None = None, stick_speed: float | None = None, use_cache: bool = True,
                 **options: Any) -> SquealBranch | HarmonicBranch:
    """Limit cycles from the first Hopf point on a path, by the route ``brakesqueal cycles`` takes
    (:func:`brakesqueal.nonlinear.models.limit_cycles`).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    axis : Axis
        The path.
    contact : {"bilateral", "unilateral"}, optional
        As in :func:`~brakesqueal.nonlinear.models.squeal_branch`.
    pads : {"auto", "exact", "quasi-static"}, optional
        As in :func:`~brakesqueal.nonlinear.models.cycle_route`.
    max_points : int, optional
        Largest number of branch points (default: the route's own).
    progress : callable, optional
        ``progress(fraction)`` after each branch point.
    pad_slope, stick_speed : float, optional
        Keep the massless Coulomb pads' rates by a slightly rising friction law (the shooting route;
        :func:`~brakesqueal.nonlinear.models.cycle_space`): another model, whose engine is built here.
    use_cache : bool, optional
        Use the on-disk code cache.
    **options
        The options of the route taken (see :func:`brakesqueal.nonlinear.models.limit_cycles`).

    Returns
    -------
    SquealBranch or HarmonicBranch
    """
    from .nonlinear.models import cycle_space
    from .nonlinear.models import limit_cycles as _limit_cycles

    space = cycle_space(space, pads=pads, pad_slope=pad_slope, stick_speed=stick_speed)
    return _limit_cycles(_engine(space, use_cache), space, axis, contact=contact, pads=pads,  # type: ignore[no-any-return]
                         max_points=max_points, progress=progress, use_cache=use_cache, **options)


@validated
def squeal_branch(space: ParameterSpace, axis: Axis, *, pad_slope: float | None = None,
                  stick_speed: float | None = None, use_cache: bool = True, **options: Any) -> SquealBranch:
    """Limit cycles by shooting from the first Hopf point on a path
    (:func:`brakesqueal.nonlinear.models.squeal_branch`).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    axis : Axis
        The path.
    pad_slope, stick_speed : float, optional
        Regularise the massless Coulomb pads (:func:`~brakesqueal.nonlinear.models.cycle_space`).
    use_cache : bool, optional
        Use the on-disk code cache.
    **options
        ``max_points``, ``tol``, ``contact``, ``ds``, ``ds_max``, ``flow_method``, ``progress``.

    Returns
    -------
    SquealBranch
    """
    from .nonlinear.models import cycle_space
    from .nonlinear.squeal import squeal_branch as _squeal_branch

    space = cycle_space(space, pad_slope=pad_slope, stick_speed=stick_speed)
    return _squeal_branch(_engine(space, use_cache), space, axis, use_cache=use_cache, **options)


@validated
def harmonic_branch(space: ParameterSpace, axis: Axis, *, use_cache: bool = True, **options: Any) -> HarmonicBranch:
    """Limit cycles of the implicit equations by harmonic balance
    (:func:`brakesqueal.nonlinear.harmonic.harmonic_branch`).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    axis : Axis
        The path.
    use_cache : bool, optional
        Use the on-disk code cache.
    **options
        The options of :func:`~brakesqueal.nonlinear.harmonic.harmonic_branch`.

    Returns
    -------
    HarmonicBranch
    """
    from .nonlinear.harmonic import harmonic_branch as _harmonic_branch

    return _harmonic_branch(_engine(space, use_cache), space, axis, use_cache=use_cache, **options)


@validated
def model_system(space: ParameterSpace, name: str, *, use_cache: bool = True) -> SmoothSystem:
    """A model as a smooth system in the parameter ``name`` (:func:`brakesqueal.nonlinear.models.model_system`).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    name : str
        The continuation parameter.
    use_cache : bool, optional
        Use the on-disk code cache.

    Returns
    -------
    SmoothSystem
    """
    from .nonlinear.models import model_system as _model_system

    return _model_system(_engine(space, use_cache), space, name, use_cache=use_cache)


@validated
def model_piecewise_system(space: ParameterSpace, name: str, *, use_cache: bool = True) -> PiecewiseSystem:
    """A model with unilateral contact as a piecewise system
    (:func:`brakesqueal.nonlinear.models.model_piecewise_system`).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    name : str
        The continuation parameter.
    use_cache : bool, optional
        Use the on-disk code cache.

    Returns
    -------
    PiecewiseSystem
    """
    from .nonlinear.models import model_piecewise_system as _model_piecewise_system

    return _model_piecewise_system(_engine(space, use_cache), space, name, use_cache=use_cache)


@validated
def exact_lyapunov(space: ParameterSpace, name: str, p0: float, *, omega: float | None = None,
                   use_cache: bool = True) -> PadHopf:
    """The first Lyapunov coefficient with the pads' true tangential dynamics
    (:func:`brakesqueal.nonlinear.implicit.exact_lyapunov`).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    name : str
        The path parameter.
    p0 : float
        A stability crossing.
    omega : float, optional
        Select the eigenvalue pair with imaginary part closest to ``omega``.
    use_cache : bool, optional
        Use the on-disk code cache.

    Returns
    -------
    PadHopf
    """
    from .nonlinear.implicit import exact_lyapunov as _exact_lyapunov

    return _exact_lyapunov(_engine(space, use_cache), space, name, p0, omega=omega, use_cache=use_cache)


@validated
def model_flow(space: ParameterSpace, name: str, *, system: SmoothSystem | None = None, use_cache: bool = True,
               rtol: Annotated[float, Range(0, 1, open_low=True, open_high=True)] = 1e-11) -> CompiledFlow:
    """The compiled flow of a model with its exact Jacobian (:func:`brakesqueal.nonlinear.compiled.model_flow`).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    name : str
        The continuation parameter.
    system : SmoothSystem, optional
        The system the flow belongs to (default :func:`model_system` ``(space, name)``).
    use_cache : bool, optional
        Use the on-disk code cache.
    rtol : float, optional
        Relative tolerance of the integrator, in (0, 1).

    Returns
    -------
    CompiledFlow
    """
    from .nonlinear.compiled import model_flow as _model_flow

    return _model_flow(_engine(space, use_cache), space, name, system=system, use_cache=use_cache, rtol=rtol)


@validated
def hopf_curves(space: ParameterSpace, x: Axis, y: Axis, *, seeds: Annotated[int, Range(1, 100)] = 5,
                max_points: Annotated[int, Range(2, 10000)] = 200, ds_max: Annotated[float, Range(1e-4, 0.5)] = 0.05,
                lyapunov: bool = True, use_cache: bool = True) -> list[HopfCurve]:
    """Every Hopf curve of the silent motion in a box of two settable parameters, with ``l1`` along it and its
    codimension-2 points (:func:`brakesqueal.region.hopf_curves`; ``docs/region.md``).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides (a model with nonlinear equations).
    x, y : Axis
        The two axes (ranges; ``log`` for logarithmic).
    seeds : int
        Lines per direction on which the curves are seeded by exact crossings.
    max_points : int
        Most points per curve.
    ds_max : float
        Largest continuation step, as a fraction of the (scaled) box.
    lyapunov : bool
        Compute ``l1`` at every point (and locate generalised-Hopf points).
    use_cache : bool
        Use the code cache.

    Returns
    -------
    list of HopfCurve
    """
    from .region import hopf_curves as _curves

    return _curves(_engine(space, use_cache), space, x, y, seeds=seeds, max_points=max_points, ds_max=ds_max,
                   lyapunov=lyapunov, use_cache=use_cache)


@validated
def region_diagram(space: ParameterSpace, x: Axis, y: Axis, *, seeds: Annotated[int, Range(1, 100)] = 5,
                   max_points: Annotated[int, Range(2, 10000)] = 200,
                   ds_max: Annotated[float, Range(1e-4, 0.5)] = 0.05, grid: Annotated[int, Range(2, 2000)] | None = 41,
                   lyapunov: bool = True, use_cache: bool = True, folds: bool = True,
                   fold_points: Annotated[int, Range(1, 50)] = 6,
                   progress: Callable[[float], None] | None = None) -> RegionResult:
    """The squeal region diagram (``brakesqueal region``): Hopf curves with ``l1`` and codimension-2 points over
    the certified stability map, the fold-of-cycles curves of the generalised-Hopf points and the shaded regions
    (:func:`brakesqueal.region.region_diagram`; ``docs/region.md``).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides (a model with nonlinear equations).
    x, y : Axis
        The two axes.
    seeds, max_points, ds_max, lyapunov, use_cache
        As :func:`hopf_curves`.
    grid : int or None
        Points per axis of the certified map drawn beneath (``None``: no map).
    folds, fold_points, progress
        As :func:`brakesqueal.region.region_diagram` (fold-of-cycles curves, slices per GH point, progress).

    Returns
    -------
    RegionResult
        ``to_dict()`` (the JSON of ``brakesqueal region``), ``text()``, ``to_dataset()``, ``plot()``.
    """
    from .region import region_diagram as _region

    return _region(_engine(space, use_cache), space, x, y, seeds=seeds, max_points=max_points, ds_max=ds_max,
                   grid=grid, lyapunov=lyapunov, use_cache=use_cache, folds=folds, fold_points=fold_points,
                   progress=progress)
