"""Maps of models without the closed-form route (``eight-dof``: a 16 x 16 state matrix): certified eigenvalue
verdicts per point, batched at the trivial silent motion, against one batched ``numpy.linalg.eigvals`` call on as
many random matrices of the same size (the floor of any eigenvalue route) in the same run.

Run by ``make bench`` (``python -m benchmarks``) or directly:
``python benchmarks/bench_model_map.py [--model NAME] [--size N]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import BenchResult, best_time, emit  # noqa: E402


def run(model: str = "eight-dof", size: int = 200) -> list[BenchResult]:
    from brakesqueal.analysis.maps import Axis, stability_map
    from brakesqueal.codegen import compile_model
    from brakesqueal.model import resolve_space

    space = resolve_space(model)
    spec = space.model
    names = [k for k in ("k_c", "k_cn", "k_ip1", "k1") if k in spec.parameters][:2]

    def axes(num: int) -> tuple[Axis, Axis]:
        a, b = (spec.parameters[k] for k in names)
        return Axis(names[0], a / 10, a * 10, num, log=True), Axis(names[1], b / 10, b * 10, num, log=True)

    stability_map(space, *axes(8))  # compile and warm up
    t_eig = best_time(lambda: stability_map(space, *axes(size)), repeat=2)
    t_vo = best_time(lambda: stability_map(space, *axes(size), eigen=False), repeat=2)
    m = stability_map(space, *axes(size)).data
    n2 = 2 * compile_model(spec).n
    nb = min(size * size, 40000)
    A = np.random.default_rng(0).normal(size=(nb, n2, n2))
    t0 = time.perf_counter()
    np.linalg.eigvals(A)
    base = nb / (time.perf_counter() - t0)
    t0 = time.perf_counter()
    w, V = np.linalg.eig(A)
    np.linalg.inv(V)
    base_vec = nb / (time.perf_counter() - t0)
    pts = size * size
    und = int(np.count_nonzero(m["status"].values == 5))
    return [
        BenchResult(f"model map ({model}, {n2}x{n2} state matrix): certified eigenvalue verdicts + max_real",
                    pts / t_eig, "points/s", base, pts / t_eig / base,
                    {"points": pts, "axes": " x ".join(names), "method": m.attrs["method"], "undecided_points": und,
                     "baseline": "one batched numpy.linalg.eigvals call on random matrices of the same size",
                     "eig_with_vectors_and_inverse_points_per_s": round(base_vec)}),
        BenchResult(f"model map ({model}): verdict only (--no-eigen)", pts / t_vo, "points/s", base, pts / t_vo / base,
                    {"note": "the verdict needs the eigenvectors' condition numbers, so it costs as much as the full "
                             "map; the former interpolated Routh test (~1e6 points/s) could not be certified"}),
    ]


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--model", default="eight-dof")
    ap.add_argument("--size", type=int, default=200)
    a = ap.parse_args()
    emit(run(a.model, a.size))
