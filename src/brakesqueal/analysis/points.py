r"""Status and certified verdict of parameter points, through the one verdict dispatcher.

Maps, sweeps, the numeric routes of crossings and critical speeds, the
boundary of a map and the plots classify parameter points through
:func:`evaluate` (arrays) and :func:`evaluate_point` (one point), which hand
them to :func:`~.verdict.decide`; a linear model's verdict is
:func:`linear_verdict` (:func:`~.verdict.decide_model`).  So a point gets the
same status, verdict, eigenvalue summary and carrier wherever it is
computed.

Consistency by construction: a point with status ``OK`` or ``OK_NONTRIVIAL``
carries a certified verdict and ``stable`` ⇔ ``max_real < 0``; a verdict
that cannot be certified gives ``UNDECIDED``; every other status is never
stable.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..status import PointStatus
from .verdict import Points, Verdicts, compact, decide, decide_model, valid_points

if TYPE_CHECKING:
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace

__all__ = ["PointVerdict", "Verdicts", "evaluate", "evaluate_arrays", "evaluate_point", "linear_verdict",
           "compact", "valid_points"]


@dataclass(frozen=True)
class PointVerdict:
    """Status and verdict of one parameter point.

    Attributes
    ----------
    status : PointStatus
        How the point was decided (or why not).
    stable : bool
        Asymptotically stable silent motion (certified); ``False`` unless
        ``status`` is ``OK`` or ``OK_NONTRIVIAL``.
    max_real : float
        Largest real part of the eigenvalues [1/s] (NaN where none was computed).
    frequency : float
        ``|Im λ| / 2π`` of that eigenvalue [Hz].
    carrier : str or None
        The mode carrying the verdict (``"disk"``, ``"pad 1"``, ``"pad 1 tangential rate"``, ...).
    method : str
        The route that decided (``"none"`` without a verdict).
    bound : float
        Error bound of ``max_real`` where the route certified the verdict through it (NaN otherwise).
    """

    status: PointStatus
    stable: bool
    max_real: float
    frequency: float
    carrier: str | None = None
    method: str = "none"
    bound: float = math.nan

    @property
    def decided(self) -> bool:
        """Whether the verdict is established (status ``OK`` or ``OK_NONTRIVIAL``)."""
        return self.status in (PointStatus.OK, PointStatus.OK_NONTRIVIAL)


def evaluate_arrays(engine: Engine, space: ParameterSpace, arr: Mapping[str, Any], names: tuple[str, ...] = (), *,
                    eigen: bool = True, valid: np.ndarray | None = None, modes: str = "all") -> Verdicts:
    """Statuses and verdicts of every point of broadcast parameter arrays.

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The parameter space (any model).
    arr : Mapping[str, ndarray]
        Every model parameter as arrays broadcastable to one shape (:meth:`ParameterSpace.arrays`).
    names : tuple of str
        The settable names that vary (the closed-form route applies when the silent motion is identically
        trivial along them).
    eigen : bool
        Also compute ``max_real`` and ``frequency`` where a cheaper certified verdict exists.
    valid : ndarray of bool, optional
        Validity mask (default :func:`valid_points`).
    modes : {"all", "disk"}
        See :func:`~.verdict.decide`.

    Returns
    -------
    Verdicts
        Arrays of the broadcast shape.
    """
    return decide(engine, space, Points(space, arr, names, valid=valid), eigen=eigen, modes=modes)


def evaluate(engine: Engine, space: ParameterSpace, values: Mapping[str, Any], *, eigen: bool = True,
             modes: str = "all") -> Verdicts:
    """Statuses and verdicts at points given by settable names of a parameter space.

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The parameter space (any model); tied names follow the values.
    values : Mapping[str, array_like]
        Settable names → values (broadcastable arrays; SI units).
    eigen : bool
        See :func:`evaluate_arrays`.
    modes : {"all", "disk"}
        See :func:`~.verdict.decide`.

    Returns
    -------
    Verdicts
        Arrays of the broadcast shape.

    Raises
    ------
    ParameterError
        A name that is not settable in ``space``.
    """
    return decide(engine, space, Points.of(space, values), eigen=eigen, modes=modes)


def evaluate_point(engine: Engine, space: ParameterSpace, values: Mapping[str, float] | None = None, *,
                   modes: str = "all") -> PointVerdict:
    """Status and verdict of one point of a parameter space.

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The parameter space.
    values : Mapping[str, float], optional
        Settable names → values (default: the space's current point).
    modes : {"all", "disk"}
        See :func:`~.verdict.decide`.

    Returns
    -------
    PointVerdict
    """
    vals = {k: np.array([float(v)]) for k, v in (values or {}).items()}
    if not vals:
        name = space.settable()[0]
        vals = {name: np.array([space.value(name)])}
    r = evaluate(engine, space, vals, modes=modes)
    return PointVerdict(PointStatus(int(r.status[0])), bool(r.stable[0]), float(r.max_real[0]),
                        float(r.frequency[0]), r.carrier_name(0), r.method_name(0), float(r.bound[0]))


def linear_verdict(lm: Any, *, modes: str = "all") -> tuple[int, float, float]:
    """Certified verdict of a linear model from every one of its eigenvalues.

    Parameters
    ----------
    lm : LinearModel
        From :func:`~.linear.linearize` (decided as the parameter point it is) or built by hand (decided from its
        matrices).
    modes : {"all", "disk"}
        See :func:`~.verdict.decide`.

    Returns
    -------
    code, max_real, frequency : int, float, float
        :data:`~.robust.STABLE`, :data:`~.robust.UNSTABLE` or
        :data:`~.robust.UNDECIDED`; the least-stable eigenvalue's real part
        [1/s] and frequency [Hz].
    """
    v = decide_model(lm, modes=modes)
    return int(v.code[0]), float(v.max_real[0]), float(v.frequency[0])

