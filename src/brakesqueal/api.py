r"""The public API of the analysis: one entry point per question, for every model.

Each function here is an *entry point*: it builds the model's
:class:`~brakesqueal.codegen.engine.Engine` once (:func:`~brakesqueal.codegen.build`,
memoized per process by the model's equations) and hands it down to the
layer that does the work; nothing below compiles or derives anything itself.
The same functions are re-exported by :mod:`brakesqueal` (``brakesqueal.linearize``,
``brakesqueal.stability_map``, ...).

Every verdict comes from the one verdict dispatcher
(:func:`brakesqueal.analysis.verdict.decide`) and names the route that
decided it and the mode that carries it.

Every function checks its arguments against its type hints before it does
anything (:func:`brakesqueal.validation.validated`): a wrong type, a NaN or
infinity where a finite number is needed or a count below one is one
:class:`~brakesqueal.errors.ParameterError` line naming the argument.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Annotated, Any, cast

from .validation import Range, validated

if TYPE_CHECKING:
    import numpy as np

    from .analysis.eigen import EigenAnalysis
    from .analysis.equilibrium import SilentMotion
    from .analysis.linear import LinearModel
    from .analysis.maps import Axis, MapSummary
    from .analysis.modes import ModeTracks
    from .analysis.points import PointVerdict, Verdicts
    from .codegen.engine import Engine
    from .model.components import ModelSpec
    from .model.matrices import MatrixSpec
    from .model.parameters import Parameters, ParameterSpace
    from .analysis.matrix_analysis import BoxResult, Reduction
    from .robust import RobustResult
    from .results import CriticalSpeedResult, CrossingResult, StabilityMap

__all__ = ["engine", "silent_motion", "linearize", "pad_rate_eigenvalues", "eigen_analysis", "evaluate",
           "evaluate_point", "stability_map", "write_map", "crossings", "critical_speeds", "critical_speeds_many",
           "modes_along"]

#: A count of at least one (points per block, crossings).
_Count = Annotated[int, Range(1)]
#: A speed bound [rad/s], above zero.
_Speed = Annotated[float, Range(0, open_low=True)]


@validated
def engine(model: ModelSpec | MatrixSpec | str | os.PathLike[str] | Parameters | ParameterSpace) -> Engine:
    """The engine of a model (a :class:`~brakesqueal.model.components.ModelSpec` or
    :class:`~brakesqueal.model.matrices.MatrixSpec`, a built-in model's name, a model file, or the model of
    parameters or a parameter space).

    Parameters
    ----------
    model : ModelSpec, MatrixSpec, str, os.PathLike, Parameters or ParameterSpace
        The model; a name that is neither a built-in model nor a model file, or anything else, is refused
        (:class:`~brakesqueal.errors.ParameterError`).

    Returns
    -------
    Engine
        Memoized per process by the model's equations.
    """
    from .codegen import build

    from .model.parameters import Parameters, ParameterSpace

    spec = model.model if isinstance(model, (Parameters, ParameterSpace)) else model
    return build(cast("ModelSpec", os.fspath(spec) if isinstance(spec, os.PathLike) else spec))


@validated
def silent_motion(params: Parameters) -> SilentMotion:
    """The silent motion (eq. 46) of a parameter set (:func:`brakesqueal.analysis.equilibrium.silent_motion`).

    Parameters
    ----------
    params : Parameters
        The model and its parameter values.

    Returns
    -------
    SilentMotion
    """
    from .analysis.equilibrium import as_parameters
    from .analysis.equilibrium import silent_motion as _silent_motion

    params = as_parameters(params)
    return _silent_motion(engine(params), params)


@validated
def linearize(params: Parameters, *, pad_rates: str = "kept") -> LinearModel:
    """Silent motion and linear model (eqs. 46-48) of a parameter set of any model.

    Parameters
    ----------
    params : Parameters
        The model and its parameter values.
    pad_rates : {"kept", "quasi-static"}
        How the massless pads' tangential rates enter (:func:`brakesqueal.analysis.linear.linearize`).

    Returns
    -------
    LinearModel
    """
    from .analysis.equilibrium import as_parameters
    from .analysis.linear import linearize as _linearize

    params = as_parameters(params)
    return _linearize(engine(params), params, pad_rates=pad_rates)


@validated
def pad_rate_eigenvalues(params: Parameters) -> np.ndarray:
    """Finite eigenvalues with the pads' tangential rates kept (``linearize(params).eigenvalues``).

    Parameters
    ----------
    params : Parameters
        The model and its parameter values.

    Returns
    -------
    ndarray of complex
        Sorted by decreasing real part [1/s].
    """
    return linearize(params).eigenvalues


@validated
def eigen_analysis(model: LinearModel | Parameters) -> EigenAnalysis:
    """Eigenvalues, modes, splits, sensitivities and verdict of a linear model or a parameter set.

    Parameters
    ----------
    model : LinearModel or Parameters
        A linear model, or a parameter set (linearized first).

    Returns
    -------
    EigenAnalysis
    """
    from .analysis.eigen import eigen_analysis as _eigen
    from .analysis.linear import LinearModel

    if isinstance(model, LinearModel):
        return _eigen(model)
    return _eigen(linearize(model))


@validated
def evaluate(space: ParameterSpace, values: Mapping[str, Any], *, eigen: bool = True, modes: str = "all") -> Verdicts:
    """Statuses and certified verdicts at points of a parameter space (:func:`brakesqueal.analysis.points.evaluate`).

    Parameters
    ----------
    space : ParameterSpace
        The parameter space (any model); tied names follow the values.
    values : Mapping[str, array_like]
        Settable names → values (broadcastable arrays; SI units).
    eigen : bool
        Also compute ``max_real`` and the frequency where a cheaper certified verdict exists.
    modes : {"all", "disk"}
        Judge every eigenvalue, or leave out the modes of a massless pad's own tangential rate.

    Returns
    -------
    Verdicts
    """
    from .analysis.points import evaluate as _evaluate

    return _evaluate(engine(space), space, values, eigen=eigen, modes=modes)


@validated
def evaluate_point(space: ParameterSpace, values: Mapping[str, Any] | None = None, *,
                   modes: str = "all") -> PointVerdict:
    """Status and certified verdict of one point of a parameter space (default: its current point).

    Parameters
    ----------
    space : ParameterSpace
        The parameter space.
    values : Mapping[str, float or str], optional
        Settable names → values (numbers, ``inf`` or expressions).
    modes : {"all", "disk"}
        Judge every eigenvalue, or leave out the modes of a massless pad's own tangential rate.

    Returns
    -------
    PointVerdict
        Status, verdict, ``max_real``, frequency, the carrier mode and the deciding route.
    """
    from .analysis.points import evaluate_point as _evaluate_point

    return _evaluate_point(engine(space), space, values, modes=modes)


@validated
def stability_map(space: ParameterSpace, x: Axis, y: Axis, *, force: bool = False, eigen: bool = True,
                  chunk_points: _Count = 1 << 18, progress: Callable[[float], None] | None = None,
                  boundary: bool = True, modes: str = "all", quantities: tuple[str, ...] | None = None
                  ) -> StabilityMap:
    """A stability map over two settable parameters (:func:`brakesqueal.analysis.maps.stability_map`).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides; tied names follow the axes.
    x, y : Axis
        The axes.
    force : bool
        Allow more than 1e9 points.
    eigen : bool
        Compute ``max_real`` and ``frequency`` (otherwise only classify).
    chunk_points : int
        Points per block (bounds the temporary memory; at least 1).
    progress : callable, optional
        Called with the completed fraction after each block.
    boundary : bool
        Also locate the stability boundary by bisection.
    modes : {"all", "disk"}
        Judge every eigenvalue, or leave out the modes of a massless pad's own tangential rate.
    quantities : tuple of str, optional
        Further quantities to store (default ``carrier`` and ``route``; :mod:`brakesqueal.analysis.quantities`).

    Returns
    -------
    StabilityMap
    """
    from .analysis.maps import stability_map as _map

    return _map(engine(space), space, x, y, force=force, eigen=eigen, chunk_points=chunk_points, progress=progress,
                boundary=boundary, modes=modes, quantities=quantities)


@validated
def write_map(space: ParameterSpace, x: Axis, y: Axis, path: str | os.PathLike[str], *, force: bool = False,
              eigen: bool = True, chunk_points: _Count = 1 << 18, progress: Callable[[float], None] | None = None,
              boundary: bool = True, modes: str = "all", quantities: tuple[str, ...] | None = None) -> MapSummary:
    """A stability map written to NetCDF block by block (:func:`brakesqueal.analysis.maps.write_map`).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    x, y : Axis
        The axes.
    path : str or os.PathLike
        The NetCDF file.
    force, eigen, chunk_points, progress, boundary, modes, quantities
        As :func:`stability_map`.

    Returns
    -------
    MapSummary
    """
    from .analysis.maps import write_map as _write

    return _write(engine(space), space, x, y, os.fspath(path), force=force, eigen=eigen, chunk_points=chunk_points,
                  progress=progress, boundary=boundary, modes=modes, quantities=quantities)


@validated
def crossings(space: ParameterSpace, axis: Axis, *, modes: str = "all") -> CrossingResult:
    """Every stability change along one settable parameter (:func:`brakesqueal.analysis.crossings.crossings`).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    axis : Axis
        The path (its ``num`` is ignored).
    modes : {"all", "disk"}
        Judge every eigenvalue, or leave out the modes of a massless pad's own tangential rate.

    Returns
    -------
    CrossingResult
    """
    from .analysis.crossings import crossings as _crossings

    return _crossings(engine(space), space, axis, modes=modes)


@validated
def critical_speeds(space: ParameterSpace, lo: _Speed = 1.0, hi: _Speed = 1e5, *, modes: str = "all"
                    ) -> CriticalSpeedResult:
    """All onsets and re-stabilisations along Ω (:func:`brakesqueal.analysis.crossings.critical_speeds`).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides; the spin must be a settable name.
    lo, hi : float
        The Ω range [rad/s], ``0 < lo < hi``.
    modes : {"all", "disk"}
        Judge every eigenvalue, or leave out the modes of a massless pad's own tangential rate.

    Returns
    -------
    CriticalSpeedResult
    """
    from .analysis.crossings import critical_speeds as _critical

    return _critical(engine(space), space, lo, hi, modes=modes)


@validated
def critical_speeds_many(space: ParameterSpace, changes: Mapping[str, Any], lo: _Speed = 1.0, hi: _Speed = 1e5,
                         max_crossings: _Count = 8, *, return_status: bool = False) -> tuple[Any, ...]:
    """Critical speeds of many parameter sets, batched (:func:`brakesqueal.analysis.crossings.critical_speeds_many`).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    changes : Mapping of str to array_like
        Settable names → values (broadcast to one length).
    lo, hi : float
        The Ω range [rad/s].
    max_crossings : int
        Columns of the outputs (at least 1).
    return_status : bool
        Also return a per-set status.

    Returns
    -------
    tuple of ndarray
        ``(crossings, directions, counts, stable_at_start[, status])``.
    """
    from .analysis.crossings import critical_speeds_many as _many

    return _many(engine(space), space, dict(changes), lo, hi, max_crossings, return_status=return_status)


@validated
def modes_along(space: ParameterSpace, name: str, start: float, stop: float, *, num: int = 200, log: bool = False,
                pad_rates: str = "kept") -> ModeTracks:
    """Mode-coupling diagram along one settable parameter (:func:`brakesqueal.analysis.modes.modes_along`).

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    name : str
        A settable name.
    start, stop : float
        The path.
    num : int
        Points of the path.
    log : bool
        Logarithmic spacing.
    pad_rates : {"kept", "quasi-static"}
        How the massless pads' tangential rates enter.

    Returns
    -------
    ModeTracks
    """
    from .analysis.modes import modes_along as _modes

    return _modes(engine(space), space, name, start, stop, num=num, log=log, pad_rates=pad_rates)


@validated
def box_eigenvalues(params: Parameters, *, re: tuple[float, float], freq: tuple[float, float], max_shifts: int = 40,
                    progress: Callable[[int, int], Any] | None = None) -> BoxResult:
    """Eigenvalues of a matrix model in a box of the complex plane, with error bounds (``brakesqueal box``).

    Parameters
    ----------
    params : Parameters
        A parameter set of a model given by coefficient matrices.
    re : (float, float)
        Range of Re λ [1/s] (e.g. ``(-50, inf)``).
    freq : (float, float)
        Frequency range [Hz], ``0 <= f_lo < f_hi``.
    max_shifts : int
        Most shift-and-invert runs before the box is declared not covered (verdict undecided).
    progress : callable, optional
        ``progress(done, total)`` per shift.

    Returns
    -------
    BoxResult
        See :func:`brakesqueal.analysis.matrix_analysis.box_analysis`.
    """
    from .analysis.matrix_analysis import box_analysis

    return box_analysis(engine(params), params, re=re, freq=freq, max_shifts=max_shifts, progress=progress)


@validated
def reduce_matrix_model(space: ParameterSpace, samples: Sequence[float], *, re: tuple[float, float],
                        freq: tuple[float, float], r: int | None = None, tol: float = 1e-10, checks: int = 2,
                        name: str | None = None, left: bool = True,
                        progress: Callable[[int, int], Any] | None = None) -> Reduction:
    """Parametric reduction of a matrix model along its spin (``brakesqueal reduce``).

    Parameters
    ----------
    space : ParameterSpace
        A model given by coefficient matrices, with its preset and overrides.
    samples : sequence of float
        Spin values [rad/s] the eigenvectors are sampled at.
    re, freq : (float, float)
        The box whose eigenvalues the reduced model keeps (:func:`box_eigenvalues`).
    r : int, optional
        Reduced dimension (default: every singular value above ``tol`` of the largest).
    tol : float
        Relative singular-value cut-off.
    checks : int
        Spins between the samples where the reduced model is checked against the full one.
    name : str, optional
        Name of the reduced model.
    left : bool
        The left eigenvectors in the basis too (the default; see :mod:`brakesqueal.analysis.reduction`).
    progress : callable, optional
        ``progress(done, total)``.

    Returns
    -------
    Reduction
        See :func:`brakesqueal.analysis.matrix_analysis.reduce_model`.
    """
    from .analysis.matrix_analysis import reduce_model

    return reduce_model(engine(space), space, samples, re=re, freq=freq, r=r, tol=tol, checks=checks, name=name,
                        left=left, progress=progress)


@validated
def robust_box(space: ParameterSpace, box: Mapping[str, Sequence[float]], *,
               max_boxes: Annotated[int, Range(1, 10_000_000)] = 4000,
               max_depth: Annotated[int, Range(1, 200)] = 60) -> RobustResult:
    """Certified robust window (``brakesqueal robust``): is every point of a parameter box stable?

    Branch and bound on enclosures of the exact characteristic quartic and its Hurwitz determinant over the box
    (:func:`brakesqueal.robust.robust_box`; ``docs/uq.md``): "stable" for every point, "unstable" with a
    certified witness point, or "undecided" with the sub-boxes left; never decided by sampling.

    Parameters
    ----------
    space : ParameterSpace
        The parameter space (a 2-DOF model with a closed form; ties apply).
    box : Mapping[str, sequence of float]
        Settable name -> ``(lo, hi)``, ``lo < hi``.
    max_boxes, max_depth : int
        Branch-and-bound budgets (sub-boxes examined, bisection depth).

    Returns
    -------
    RobustResult
    """
    from .robust import robust_box as _robust_box

    return _robust_box(engine(space), space, box, max_boxes=max_boxes, max_depth=max_depth)
