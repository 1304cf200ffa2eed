"""Shared helpers of the benchmark scripts: a result record, best-of timing and output.

Every script prints a human-readable table and, as its last line, one JSON
array of its results (read by ``python -m benchmarks``).  Ratios are always
against a baseline run in the same process.
"""

from __future__ import annotations

import json
import math
import os
import time
from dataclasses import asdict, dataclass, field
from typing import Any, Callable


@dataclass
class BenchResult:
    """One measured number, its baseline from the same run and their ratio."""

    metric: str
    value: float
    unit: str
    baseline: float | None = None
    ratio: float | None = None
    details: dict[str, Any] = field(default_factory=dict)

    def clean(self) -> dict[str, Any]:
        d = asdict(self)
        for k in ("value", "baseline", "ratio"):
            if isinstance(d[k], float) and not math.isfinite(d[k]):
                d[k] = None
        return d


def user_env(**extra: str) -> dict[str, str]:
    """The environment for a command timed as a user runs it: this one, with Python's bytecode cache allowed.

    A user's installed package has its ``.pyc`` files (pip compiles them on install; an editable install
    writes them on first import).  A shell that sets ``PYTHONDONTWRITEBYTECODE`` (some CI and container
    images do) makes every start compile the package's sources again, about 40 ms of a ``linearize``: the
    timed commands run without it, and the first (warm-up) run of each writes the bytecode.
    """
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env.update(extra)
    return env


def best_time(fn: Callable[[], Any], *, repeat: int = 5, min_time: float = 0.0) -> float:
    """Best wall time of ``repeat`` calls [s] (each call repeated until ``min_time`` has passed).

    A call slower than ``5 * max(min_time, 1 s)`` is not repeated: its time is already well above the noise.
    """
    best = math.inf
    for _ in range(repeat):
        n, t0 = 0, time.perf_counter()
        while True:
            fn()
            n += 1
            dt = time.perf_counter() - t0
            if dt >= min_time:
                break
        best = min(best, dt / n)
        if best > 5 * max(min_time, 1.0):
            break
    return best


def emit(results: list[BenchResult]) -> None:
    """Print the table and the JSON line."""
    for r in results:
        base = "" if r.baseline is None else f" (baseline {r.baseline:.4g} {r.unit})"
        ratio = "" if r.ratio is None or not math.isfinite(r.ratio) else f" ratio {r.ratio:.3g}x"
        print(f"  {r.metric}: {r.value:.4g} {r.unit}{base}{ratio}")
        for k, v in r.details.items():
            print(f"    {k}: {v}")
    print(json.dumps([r.clean() for r in results]))
