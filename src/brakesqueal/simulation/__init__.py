"""Nonlinear time simulation of any model (paper eq. 44, generalized): one compiled integrator.

See :func:`simulate`, :func:`simulation_model`, :mod:`brakesqueal.simulation.estimate`
(growth rate and frequency from samples) and ``docs/simulation.md``.
"""

from __future__ import annotations

from ._integrate import (
    METHODS,
    POINTS_PER_PERIOD,
    START_AMPLITUDE,
    SilentState,
    SimulationModel,
    default_model,
    estimation_rate,
    simulate,
    simulation_model,
)
from .estimate import LinearModes, ModeEstimate, dominant_mode, linear_modes, matrix_pencil, modal_projection
from .trajectory import EstimationRecord, Summary, Trajectory, envelope, fit_growth_frequency, summarize

__all__ = [
    "METHODS", "POINTS_PER_PERIOD", "START_AMPLITUDE", "EstimationRecord", "LinearModes", "ModeEstimate",
    "SilentState", "SimulationModel", "Summary", "Trajectory", "default_model", "dominant_mode", "envelope",
    "estimation_rate", "fit_growth_frequency", "linear_modes", "matrix_pencil", "modal_projection", "simulate",
    "simulation_model", "summarize",
]  # fmt: skip
