"""Nonlinear time simulation of the wobbling-disk model (paper eq. 44).

See :func:`simulate`, :mod:`brakesqueal.simulation.estimate` (growth rate and
frequency from samples) and ``docs/simulation.md``.
"""

from __future__ import annotations

from ._integrate import METHODS, POINTS_PER_PERIOD, START_AMPLITUDE, SimulationModel, default_model, simulate
from .estimate import LinearModes, ModeEstimate, dominant_mode, linear_modes, matrix_pencil, modal_projection
from .trajectory import EstimationRecord, Summary, Trajectory, envelope, fit_growth_frequency, summarize

__all__ = [
    "METHODS", "POINTS_PER_PERIOD", "START_AMPLITUDE", "EstimationRecord", "LinearModes", "ModeEstimate",
    "SimulationModel", "Summary", "Trajectory", "default_model", "dominant_mode", "envelope", "fit_growth_frequency",
    "linear_modes", "matrix_pencil", "modal_projection", "simulate", "summarize",
]  # fmt: skip
