"""``brakesqueal explore`` for the browser tests, with one deterministic gate for the cancel test.

A simulation asked for with ``t_end == GATED_T_END`` waits at its first progress
report until the lane cancels it (its progress callback then raises
``Cancelled``), for at most ``GATE_SECONDS``; then it runs as usual.  So the
cancel test does not race the simulation, which is now faster than a click
under load (the race made CI fail once: the 5 s run finished before Cancel).
Every other request runs the explorer unchanged.
"""

from __future__ import annotations

import sys
import time
from typing import Any

GATED_T_END = 4.375
GATE_SECONDS = 300.0


def _install_gate() -> None:
    from brakesqueal.explorer import app

    real = app.simulation_view

    def gated(space: Any, t_end: float, *, progress: Any = None) -> Any:
        if progress is not None and t_end == GATED_T_END:
            deadline = time.monotonic() + GATE_SECONDS
            while time.monotonic() < deadline:
                progress(0.0)  # raises Cancelled once the lane is cancelled
                time.sleep(0.01)
        return real(space, t_end, progress=progress)

    app.simulation_view = gated


if __name__ == "__main__":
    _install_gate()
    from brakesqueal.cli import main

    sys.argv[0] = "brakesqueal"
    sys.exit(main())
