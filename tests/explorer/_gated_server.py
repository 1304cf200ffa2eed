"""``brakesqueal explore`` for the browser tests, with deterministic gates for the cancel tests.

A simulation asked for with ``t_end == GATED_T_END`` waits at its first progress
report until the lane cancels it (the explorer kills the child process it runs
in), for at most ``GATE_SECONDS``; then it runs as usual.  So the
cancel test does not race the simulation, which is now faster than a click
under load (the race made CI fail once: the 5 s run finished before Cancel).
Likewise limit cycles asked for at ``Omega == GATED_OMEGA`` wait at their
progress callback (the one the lane passes to ``cycles_view`` and on to the
branch) until cancelled.  Every other request runs the explorer unchanged.
"""

from __future__ import annotations

import sys
import time
from typing import Any

GATED_T_END = 4.375
#: limit cycles of a state with this value of ``Omega`` are held at their progress callback
GATED_OMEGA = 36.125
GATE_SECONDS = 300.0


def _hold(progress: Any) -> None:
    """Report no progress until ``progress`` raises (the lane was cancelled), for at most GATE_SECONDS."""
    deadline = time.monotonic() + GATE_SECONDS
    while time.monotonic() < deadline:
        progress(0.0)  # raises Cancelled once the lane is cancelled
        time.sleep(0.01)


def gated_simulation_view(space: Any, t_end: float, *, progress: Any = None) -> Any:
    """The explorer's simulation, held at its first progress report when ``t_end == GATED_T_END``.

    Module-level: the explorer runs it in a child process (pickled by reference; the child imports this
    file as its main module).
    """
    from brakesqueal.explorer.state import simulation_view

    if progress is not None and t_end == GATED_T_END:
        _hold(progress)
    return simulation_view(space, t_end, progress=progress)


def gated_cycles_view(space: Any, along: str, rng: Any, *, progress: Any = None) -> Any:
    """The explorer's limit cycles, held at their progress callback when ``Omega == GATED_OMEGA``."""
    from brakesqueal.explorer.state import cycles_view

    if progress is not None and "Omega" in space.settable() and space.value("Omega") == GATED_OMEGA:
        _hold(progress)
    return cycles_view(space, along, rng, progress=progress)


def _install_gate() -> None:
    from brakesqueal.explorer import app

    app.simulation_view = gated_simulation_view
    app.cycles_view = gated_cycles_view


if __name__ == "__main__":
    _install_gate()
    from brakesqueal.cli import main

    sys.argv[0] = "brakesqueal"
    sys.exit(main())
