"""Public entry point of the nonlinear time simulation (re-exports :mod:`brakesqueal.simulation`)."""

from __future__ import annotations

from .simulation import METHODS, SimulationModel, Summary, Trajectory, default_model, simulate

__all__ = ["METHODS", "SimulationModel", "Summary", "Trajectory", "default_model", "simulate"]
