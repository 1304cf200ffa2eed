"""A 1e5-evaluation Sobol' study on the paper's model end to end (issue 27, item 1): seconds.

The study: ``paper-fig2`` at Omega = 16 pi rad/s, four inputs (mu uniform, k_ip lognormal, d1 truncnormal, d2
uniform), ``N = 2^14``: ``(d + 2) N = 98 304`` evaluations.  Measured in one process, warm (the model's kernels
loaded and the study run once before timing):

* :func:`brakesqueal.uq.run_uq` from the study file to the indices of max Re λ, squeal and the frequency, their
  bootstrap intervals (999 resamples) and P(squeal) (target: <= 2 s); the baseline is the evaluation of the same
  98 304 design points alone (:func:`brakesqueal.sweep.compute.compute_chunk`, the batched certified evaluator
  every study uses), so the ratio is the cost of the whole study relative to its evaluations;
* the same with ``per_mode=True`` (indices of Re λ and the frequency of both tracked modes as well);
* the command ``brakesqueal uq STUDY --format json`` in a fresh process (interpreter start and imports
  included; the model's kernels read from the cache), for reference.

Run by ``make bench`` (``python -m benchmarks``) or directly: ``python benchmarks/bench_uq.py [--n N]``.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import BenchResult, best_time, emit, user_env  # noqa: E402

STUDY = """\
name = "bench-uq"
preset = "paper-fig2"
[parameters]
Omega = 50.26548245743669
[distributions]
mu = {{ uniform = [0.35, 0.55] }}
k_ip = {{ lognormal = [1e8, 0.7] }}
d1 = {{ truncnormal = [5.0, 2.0, 0.5, 10.0] }}
d2 = {{ uniform = [0.5, 10.0] }}
[samples]
n = {n}
seed = 2026
"""


def run(n: int = 1 << 14) -> list[BenchResult]:
    from brakesqueal.sweep import load_study
    from brakesqueal.sweep.compute import ChunkSpec, compute_chunk
    from brakesqueal.uq import run_uq
    from brakesqueal.uq._design import design_study

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "bench-uq.toml"
        path.write_text(STUDY.format(n=n), encoding="utf-8")
        small = Path(tmp) / "small.toml"
        small.write_text(STUDY.format(n=64), encoding="utf-8")
        run_uq(small, per_mode=True)  # warm: kernels, scipy.stats
        ds = run_uq(path).dataset
        evals = int(ds.attrs["n_evaluations"])
        t_uq = best_time(lambda: run_uq(path), repeat=3)
        t_modes = best_time(lambda: run_uq(path, per_mode=True), repeat=3)

        st = design_study(load_study(path), ("max_real", "frequency"))
        spec, samples = ChunkSpec.from_study(st), st.samples()

        def evaluate() -> None:
            for c in range(st.n_chunks):
                (r,) = st.region(c)
                compute_chunk(spec, {k: v[r] for k, v in samples.items()})

        t_eval = best_time(evaluate, repeat=3)
        cmd = [sys.executable, "-m", "brakesqueal", "uq", str(path), "--format", "json", "--no-progress"]
        env = user_env()
        subprocess.run(cmd, check=True, capture_output=True, env=env)  # warm: bytecode, kernel cache
        t_cli = min(_timed(cmd, env) for _ in range(3))
    common = {"evaluations": evals, "inputs": 4, "n_base": n, "resamples": 999, "no_verdict": ds.attrs["no_verdict"],
              "p_squeal": round(float(ds["p_squeal"]), 4), "machine": "2 vCPU shared with other jobs (noisy)"}
    return [
        BenchResult("1e5-evaluation Sobol' study, paper-fig2, run_uq end to end (warm)", t_uq, "s", t_eval,
                    t_uq / t_eval, {**common, "baseline": "the design's evaluations alone (compute_chunk), same "
                                    "process", "target": "<= 2 s"}),
        BenchResult("the same with per-mode indices (run_uq per_mode=True)", t_modes, "s", t_uq, t_modes / t_uq,
                    {"modes": int(ds.sizes.get("mode", 2)), "baseline": "run_uq without per-mode indices"}),
        BenchResult("the same as the command 'brakesqueal uq --format json' (fresh process)", t_cli, "s", t_uq,
                    t_cli / t_uq, {"baseline": "run_uq in a warm process",
                                   "note": "includes interpreter start and the imports (scipy.stats, xarray, "
                                           "dask, numba: about 1.5-2.5 s on this machine)"}),
    ]


def _timed(cmd: list[str], env: dict[str, str]) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True, env=env)
    return time.perf_counter() - t0


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--n", type=int, default=1 << 14, help="base sample count N (evaluations: 6 N)")
    a = ap.parse_args()
    emit(run(a.n))
