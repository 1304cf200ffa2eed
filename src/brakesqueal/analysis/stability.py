"""Stability analysis of the silent motion for any model: public entry points.

* :func:`stability_map` — map over two settable names of a parameter space
  → :class:`~brakesqueal.results.StabilityMap`;
* :func:`crossings` — stability changes along one settable name;
* :func:`critical_speeds` / :func:`critical_speeds_many` — all onsets and
  re-stabilisations along the spin rate Ω;
* :func:`evaluate` / :func:`evaluate_point` — status and certified verdict of
  points (the one per-point evaluator behind all of them);
* :func:`eigen_analysis` — eigenvalues, modes, sensitivities, verdict.

Every function takes a :class:`~brakesqueal.model.parameters.ParameterSpace`
of any model and chooses its route by what the model allows (closed-form
kernels for two coordinates with rate-free pads and a trivial silent motion,
certified per-point eigenvalue verdicts otherwise), recording it in the
result's ``method``.  Implementation modules: :mod:`.points`, :mod:`.kernels`
(generated and compiled criteria), :mod:`.robust`, :mod:`.maps`,
:mod:`.crossings`, :mod:`.eigen`.
"""

from __future__ import annotations

from ..model.parameters import ParameterSpace
from .crossings import critical_speeds, critical_speeds_many, crossings
from .eigen import EigenAnalysis, Verdict, eigen_analysis
from .kernels import hurwitz_h3, hurwitz_stable, quartic_coefficients
from .maps import Axis, classify_grid, parse_axis, stability_map
from .points import PointVerdict, Points, evaluate, evaluate_point

__all__ = [
    "Axis", "EigenAnalysis", "ParameterSpace", "PointVerdict", "Points", "Verdict", "classify_grid",
    "critical_speeds", "critical_speeds_many", "crossings", "eigen_analysis", "evaluate", "evaluate_point",
    "hurwitz_h3", "hurwitz_stable", "parse_axis", "quartic_coefficients", "stability_map",
]
