"""Nonlinear time simulation of any model (paper eq. 44, generalized): one compiled integrator.

See :func:`simulate`, :func:`simulation_model` (the simulation kernels of an
:class:`~brakesqueal.codegen.engine.Engine`), :mod:`brakesqueal.simulation.estimate`
(growth rate and frequency from samples) and ``docs/simulation.md``.  The public
:func:`brakesqueal.simulate` builds the engine from the parameters.
"""

from __future__ import annotations

from ._integrate import METHODS, EventMode, POINTS_PER_PERIOD, START_AMPLITUDE, estimation_rate, simulate
from ._model import SilentState, SimulationModel, simulation_model, state_jacobian
from .estimate import LinearModes, ModeEstimate, dominant_mode, linear_modes, matrix_pencil, modal_projection
from .trajectory import EstimationRecord, Summary, Trajectory, envelope, fit_growth_frequency, summarize

__all__ = [
    "METHODS", "POINTS_PER_PERIOD", "START_AMPLITUDE", "EstimationRecord", "EventMode", "LinearModes", "ModeEstimate",
    "SilentState", "SimulationModel", "Summary", "Trajectory", "dominant_mode", "envelope",
    "estimation_rate", "fit_growth_frequency", "linear_modes", "matrix_pencil", "modal_projection", "simulate",
    "simulation_model", "state_jacobian", "summarize",
]  # fmt: skip
