"""Benchmark helpers and ``brakesqueal bench derive``.

Every benchmark measures the package's way and a baseline *in the same run*
and reports ``{"metric", "value", "unit", "baseline", "ratio"}``; nothing here
is asserted by the test suite (timings live in benchmarks, not tests).
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass, field
from typing import Any, Callable

__all__ = ["BenchResult", "best_time", "report", "bench_derive"]


@dataclass
class BenchResult:
    """One benchmark measurement.

    Attributes
    ----------
    metric : str
        What was measured.
    value : float
        The package's figure.
    unit : str
        Unit of ``value`` and ``baseline`` (e.g. ``"s"`` or ``"points/s"``).
    baseline : float
        The baseline's figure, measured in the same run.
    ratio : float
        Speed-up: ``baseline / value`` for times, ``value / baseline`` for rates.
    details : dict
        Extra context (sizes, baseline description).
    """

    metric: str
    value: float
    unit: str
    baseline: float
    ratio: float
    details: dict[str, Any] = field(default_factory=dict)


def best_time(fn: Callable[[], Any], *, repeat: int = 5, min_time: float = 0.0) -> float:
    """Best wall time of ``fn()`` over ``repeat`` runs (seconds)."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
        if best > 5 * max(min_time, 1.0):
            break
    return best


def _finite(d: dict[str, Any]) -> dict[str, Any]:
    """Non-finite numbers (e.g. a skipped baseline) become ``None`` so the JSON stays valid."""
    return {k: (None if isinstance(v, float) and v != v or v in (float("inf"), float("-inf")) else v)
            for k, v in d.items()}  # fmt: skip


def report(results: list[BenchResult], fmt: str) -> str:
    """Render results as a text table, or as JSON: one object with the keys ``metric``, ``value``,
    ``unit``, ``baseline``, ``ratio`` (and ``details``) for the headline result, the others in ``more``."""
    if fmt == "json":
        data = _finite(asdict(results[0]))
        if len(results) > 1:
            data["more"] = [_finite(asdict(r)) for r in results[1:]]
        return json.dumps(data, indent=2, allow_nan=False) + "\n"
    lines = [f"{'metric':58s} {'value':>12s} {'baseline':>12s} {'unit':>10s} {'ratio':>9s}"]
    for r in results:
        lines.append(f"{r.metric:58s} {r.value:12.4g} {r.baseline:12.4g} {r.unit:>10s} {r.ratio:8.1f}x")
        for k, v in r.details.items():
            lines.append(f"    {k}: {v}")
    return "\n".join(lines) + "\n"


def _cold_derivation() -> None:
    """What a cache miss costs: derive, differentiate, linearize at q_m0 = 0, simplify, generate code."""
    from .numeric.compiled import generate_source
    from .symbolic.linearize import closed_form

    closed_form.cache_clear()
    generate_source()
    closed_form("general")


def _sympy_baseline() -> None:
    """Straightforward SymPy: build the same equations, differentiate, substitute the operating point."""
    import sympy as sp

    from .symbolic.linearize import linear_matrices, trivial_blocks
    from .symbolic.model import derive_equations

    eq = derive_equations("sympy")
    linear_matrices(trivial_blocks(eq), sp)


def _equations_only(backend: str, kronecker: bool) -> Callable[[], Any]:
    from .symbolic.model import derive_equations

    return lambda: derive_equations(backend, kronecker=kronecker)  # type: ignore[arg-type]


def bench_derive(*, baseline: bool = True) -> list[BenchResult]:
    """Cold derivation + symbolic linearization vs. a SymPy baseline, and Kronecker vs. chain rule.

    Returns
    -------
    list of BenchResult
        First the headline ``derive`` result, then the Kronecker comparison in
        both backends.
    """
    t0 = time.perf_counter()
    _cold_derivation()  # first call also pays the imports, as a user's first run does
    first = time.perf_counter() - t0
    cold = min(first, best_time(_cold_derivation, repeat=3))
    base = best_time(_sympy_baseline, repeat=1) if baseline else float("nan")
    out = [
        BenchResult(
            "derive: equations + symbolic linearization (general model, cold cache)",
            cold, "s", base, base / cold,
            {"first_call_incl_imports_s": round(first, 4),
             "baseline": "same procedure in plain SymPy (build, differentiate, substitute q_m0 = 0)"},
        )  # fmt: skip
    ]
    for backend, rep in (("symengine", 20), ("sympy", 2)):
        tk = best_time(_equations_only(backend, True), repeat=rep)
        tc = best_time(_equations_only(backend, False), repeat=rep)
        out.append(
            BenchResult(
                f"nonlinear equations, Kronecker form vs chain rule ({backend})",
                tk, "s", tc, tc / tk,
                {"saving_percent": round(100 * (1 - tk / tc), 1), "paper_claim_percent": 5},
            )  # fmt: skip
        )
    return out
