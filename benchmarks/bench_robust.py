"""Certified robust-box decisions on the paper's 2-DOF model (issue 27, item 4): boxes per second.

2 000 random boxes of ``paper-fig2`` over ``(mu, k_ip)`` (random centres over Fig. 2, relative half-widths from
1e-4 to 0.3, a fifth of them centred on the crossings of ``mu = 0.5``) decided together by
:func:`brakesqueal.robust.decide_boxes` (vectorised branch and bound, witnesses confirmed by the batched verdict
dispatcher), against the baseline in the same process: the same boxes decided one at a time by
:func:`brakesqueal.robust.robust_box` (a subset).  Target: >= 1e3 boxes/s.

Run by ``make bench`` (``python -m benchmarks``) or directly: ``python benchmarks/bench_robust.py [--boxes N]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import BenchResult, best_time, emit  # noqa: E402

K_LOW, K_HIGH = 2.308813e5, 1.866013e6


def _boxes(n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    c = np.stack([rng.uniform(0.05, 1.0, n), 10 ** rng.uniform(5, 7, n)], axis=1)
    near = rng.uniform(0, 1, n) < 0.2
    c[near, 0] = rng.uniform(0.49, 0.51, near.sum())
    c[near, 1] = np.where(rng.uniform(0, 1, near.sum()) < 0.5, K_LOW, K_HIGH) * (1 + rng.normal(0, 1e-3, near.sum()))
    w = 10 ** rng.uniform(-4, np.log10(0.3), (n, 2))
    return c * (1 - w), c * (1 + w)


def run(boxes: int = 2000, baseline_boxes: int = 200) -> list[BenchResult]:
    import brakesqueal
    from brakesqueal.model import resolve_space
    from brakesqueal.robust import decide_boxes, robust_box

    space = resolve_space(preset="paper-fig2")
    eng = brakesqueal.engine(space)
    lo, hi = _boxes(boxes)
    decide_boxes(eng, space, ["mu", "k_ip"], lo[:64], hi[:64])  # warm: table, dispatcher kernels
    t = best_time(lambda: decide_boxes(eng, space, ["mu", "k_ip"], lo, hi), repeat=3)
    v = decide_boxes(eng, space, ["mu", "k_ip"], lo, hi)
    t0 = time.perf_counter()
    for i in range(baseline_boxes):
        robust_box(eng, space, {"mu": (lo[i, 0], hi[i, 0]), "k_ip": (lo[i, 1], hi[i, 1])}, max_boxes=400)
    base = baseline_boxes / (time.perf_counter() - t0)
    rate = boxes / t
    counts = {k: int(np.sum(np.asarray(v.verdicts) == k)) for k in ("stable", "unstable", "undecided")}
    return [BenchResult("certified robust-box decisions, paper-fig2 over (mu, k_ip) (decide_boxes)", rate,
                        "boxes/s", base, rate / base,
                        {"boxes": boxes, "verdicts": counts, "sub_boxes_examined": int(v.examined.sum()),
                         "baseline": "robust_box one box at a time (same budget), same process",
                         "target": ">= 1e3 boxes/s", "machine": "2 vCPU shared with other jobs (noisy)"})]


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--boxes", type=int, default=2000)
    a = ap.parse_args()
    emit(run(a.boxes))
