"""Cold derivation + symbolic linearization vs. plain SymPy, and the paper's Kronecker claim (5 %).

Run by ``make bench`` (``python -m benchmarks``) or directly: ``python benchmarks/bench_derive.py [--no-baseline]``.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import BenchResult, best_time, emit  # noqa: E402


def cold_derivation() -> None:
    """What a cache miss costs: assemble, differentiate, generate code, closed form at q_m0 = 0."""
    from brakesqueal.codegen.compiled import _generate
    from brakesqueal.model import get_model
    from brakesqueal.symbolic.linearize import closed_form

    closed_form.cache_clear()
    _generate(get_model("paper"))
    closed_form("general")


def sympy_baseline() -> None:
    """Straightforward SymPy: build the same equations, differentiate, substitute the operating point."""
    import sympy as sp

    from brakesqueal.model import get_model
    from brakesqueal.symbolic.assemble import build_equations
    from brakesqueal.symbolic.linearize import linear_matrices, trivial_blocks

    linear_matrices(trivial_blocks(build_equations(get_model("paper"), "sympy")), sp)


def equations_only(backend: str, kronecker: bool):  # type: ignore[no-untyped-def]
    from brakesqueal.model import get_model
    from brakesqueal.symbolic.assemble import build_equations

    spec = get_model("paper")
    return lambda: build_equations(spec, backend, kronecker=kronecker)  # type: ignore[arg-type]


def run(baseline: bool = True) -> list[BenchResult]:
    t0 = time.perf_counter()
    cold_derivation()  # the first call also pays the imports, as a user's first run does
    first = time.perf_counter() - t0
    cold = min(first, best_time(cold_derivation, repeat=3))
    base = best_time(sympy_baseline, repeat=1) if baseline else float("nan")
    out = [BenchResult("derive: equations + code generation + closed form (paper model, cold cache)", cold, "s",
                       base, base / cold, {"first_call_incl_imports_s": round(first, 4),
                                           "baseline": "same procedure in plain SymPy (build, differentiate, "
                                                       "substitute q_m0 = 0)"})]
    for backend, rep in (("symengine", 20), ("sympy", 2)):
        tk = best_time(equations_only(backend, True), repeat=rep)
        tc = best_time(equations_only(backend, False), repeat=rep)
        out.append(BenchResult(f"nonlinear equations, Kronecker form vs chain rule ({backend})", tk, "s", tc, tc / tk,
                               {"saving_percent": round(100 * (1 - tk / tc), 1), "paper_claim_percent": 5}))
    return out


if __name__ == "__main__":
    emit(run(baseline="--no-baseline" not in sys.argv))
