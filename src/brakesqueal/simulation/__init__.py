"""Nonlinear time simulation of the wobbling-disk model (paper eq. 44).

See :func:`simulate` and ``docs/simulation.md``.
"""

from __future__ import annotations

from ._integrate import METHODS, SimulationModel, default_model, simulate
from .trajectory import Summary, Trajectory, envelope, fit_growth_frequency

__all__ = [
    "METHODS", "SimulationModel", "Summary", "Trajectory", "default_model", "envelope",
    "fit_growth_frequency", "simulate",
]  # fmt: skip
