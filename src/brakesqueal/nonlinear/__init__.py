"""Nonlinear analysis after onset: Hopf criticality, periodic orbits, their continuation and bifurcations.

Generic machinery, independent of the brake models: any smooth system
``x' = f(x, p)`` (:class:`SmoothSystem`) or piecewise-smooth system with
guards and resets (:class:`PiecewiseSystem`).  See ``docs/nonlinear.md``.

* :func:`first_lyapunov` — first Lyapunov coefficient (Kuznetsov's projection
  formula, MatCont's normalisation), criticality, transversality, predicted
  amplitude and frequency of the emerging cycles (:class:`HopfResult`);
* :func:`find_periodic_orbit` — (multiple) shooting with a Poincaré phase
  condition, Floquet multipliers, stability (:class:`PeriodicOrbit`);
* :func:`hill_exponents`, :func:`stability_verdict`, :func:`cross_check` —
  verified Floquet stability: Hill's method on a shot orbit, verdicts
  (``"stable"``, ``"unstable"``, ``"undecided"``) bounded by the trivial
  multiplier's error (:mod:`.floquet`);
* :func:`continue_cycles` — pseudo-arclength continuation of cycles from a Hopf
  point or an orbit, detection and location of folds (LPC), period doubling
  (PD), Neimark–Sacker (NS), branch points (BPC), grazing (GR)
  (:class:`CycleBranch`, an xarray Dataset and a figure);
* flows with sensitivities: :class:`ScipyFlow` (default, SciPy DOP853,
  variational equations, events with saltation matrices) and
  :class:`CompiledFlow` (numba DOP853, imported on first use).
"""

from __future__ import annotations

from typing import Any

from .continuation import SPECIAL_KINDS, CycleBranch, SpecialPoint, continue_cycles
from .floquet import VERDICTS, HillResult, cross_check, hill_exponents, multiplier_accuracy, stability_verdict
from .flow import Event, Flow, FlowError, FlowResult, ScipyFlow
from .hopf import CycleGuess, HopfResult, first_lyapunov
from .periodic import PeriodicOrbit, ShootingError, find_periodic_orbit, floquet_multipliers
from .system import PiecewiseSystem, SmoothSystem, Transition, fd_bilinear, fd_dp, fd_trilinear

__all__ = [
    "SmoothSystem", "PiecewiseSystem", "Transition", "fd_bilinear", "fd_trilinear", "fd_dp",
    "first_lyapunov", "HopfResult", "CycleGuess",
    "Flow", "FlowResult", "FlowError", "Event", "ScipyFlow", "CompiledFlow", "compiled_system",
    "find_periodic_orbit", "PeriodicOrbit", "ShootingError", "floquet_multipliers",
    "hill_exponents", "HillResult", "stability_verdict", "multiplier_accuracy", "cross_check", "VERDICTS",
    "continue_cycles", "CycleBranch", "SpecialPoint", "SPECIAL_KINDS",
]  # fmt: skip

_LAZY = {"CompiledFlow": "compiled", "compiled_system": "compiled"}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module 'brakesqueal.nonlinear' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
