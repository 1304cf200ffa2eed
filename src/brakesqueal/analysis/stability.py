"""Stability analysis of the silent motion: public entry points.

* :func:`stability_map` — map over two settable parameters of a preset
  (compiled exact Hurwitz kernel; numeric linearization where the silent
  motion is non-trivial) → :class:`~brakesqueal.results.StabilityMap`;
* :func:`crossings` — exact stability changes along one parameter;
* :func:`critical_speeds` — all onsets / re-stabilisations along Ω;
* :func:`eigen_analysis` — eigenvalues, modes, sensitivities, verdict.

Implementation modules: :mod:`.space` (parameter spaces), :mod:`.kernels`
(generated and compiled criteria), :mod:`.maps`, :mod:`.crossings`,
:mod:`.eigen`.
"""

from __future__ import annotations

from .crossings import critical_speeds, critical_speeds_many, crossings
from .eigen import EigenAnalysis, Verdict, eigen_analysis
from .kernels import hurwitz_h3, hurwitz_stable, quartic_coefficients
from .maps import Axis, classify_grid, parse_axis, stability_map
from .space import ParameterSpace

__all__ = [
    "Axis", "EigenAnalysis", "ParameterSpace", "Verdict", "classify_grid", "critical_speeds",
    "critical_speeds_many", "crossings", "eigen_analysis", "hurwitz_h3", "hurwitz_stable", "parse_axis",
    "quartic_coefficients", "stability_map",
]
