"""Stability analysis of the silent motion for any model: the layer's entry points (each takes the model's engine).

* :func:`stability_map` / :func:`write_map` — map over two settable names of a parameter space;
* :func:`crossings` — stability changes along one settable name;
* :func:`critical_speeds` / :func:`critical_speeds_many` — all onsets and re-stabilisations along the spin Ω;
* :func:`evaluate` / :func:`evaluate_point` — status and certified verdict of points;
* :func:`eigen_analysis` — eigenvalues, modes, sensitivities, verdict.

Every verdict comes from the one dispatcher, :func:`~.verdict.decide`.  The public API without engines is
:mod:`brakesqueal.api` (re-exported by :mod:`brakesqueal`).
"""

from __future__ import annotations

from ..model.parameters import ParameterSpace
from .crossings import critical_speeds, critical_speeds_many, crossings
from .eigen import EigenAnalysis, Verdict, eigen_analysis
from .kernels import hurwitz_h3, hurwitz_stable, quartic_coefficients
from .maps import Axis, classify_grid, parse_axis, stability_map, write_map
from .points import PointVerdict, evaluate, evaluate_point
from .verdict import Verdicts, decide

__all__ = [
    "Axis", "EigenAnalysis", "ParameterSpace", "PointVerdict", "Verdict", "Verdicts", "classify_grid",
    "critical_speeds", "critical_speeds_many", "crossings", "decide", "eigen_analysis", "evaluate", "evaluate_point",
    "hurwitz_h3", "hurwitz_stable", "parse_axis", "quartic_coefficients", "stability_map", "write_map",
]
