"""The simulation's interrupt helpers: :mod:`brakesqueal.interrupts` (kept for the integrator's imports)."""

from __future__ import annotations

from ..interrupts import check_interrupt, interrupt_guard

__all__ = ["interrupt_guard", "check_interrupt"]
