"""Peak memory of ``brakesqueal map`` as the map grows: 1e6, 1e7 and 1e8 points (target: 1e8 within 2 GiB).

Commands (paper-fig2, with ``max_real`` and ``frequency``; a fresh process each, warm cache)::

    brakesqueal map --x k_ip=1e5:1e10:NX:log --y mu=0.05:1:NY --out m.nc

with ``NX x NY`` = 1000 x 1000, 10000 x 1000 and 10000 x 10000, the
1e8-point map once more with ``--no-eigen``, and a 1e8-point map with one very
long axis (``NX = 5e7``, ``NY = 2``: rows are cut into pieces, axis values are
formed per block).  The file is written block by
block (:class:`brakesqueal.results.MapFile`), so the peak RSS should hardly
grow with the map: the baseline of every row is the 1e6-point map run in the
same session, and the ratio is peak RSS(n) / peak RSS(1e6).  ``extra_bytes_per_point``
is the growth beyond the 1e6-point run divided by the extra points.  Maps of at
most 1.6e7 points also keep ``stable`` and ``status`` (2 bytes per point) and
locate the stability boundary (contour of the whole grid): the 1e7 row shows
that cost, the 1e8 row (no boundary) the bounded writer alone.  The 1e8-point
runs write 1 GB files into a temporary directory and take 5-15 s each
(about 40 s in all on a quiet machine); ``BRAKESQUEAL_BENCH_MAP_1E8=0`` leaves them out.

Peak RSS from :func:`os.wait4`; the load average (:func:`os.getloadavg`) is
recorded with every run: on a shared machine wall times are noisy, the peak
RSS much less so.

Run by ``make bench`` (``python -m benchmarks``) or directly:
``python benchmarks/bench_map_memory.py``.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_map_cli import CPU, measure  # noqa: E402
from common import BenchResult, emit, user_env  # noqa: E402

SIZES = [(1000, 1000), (10000, 1000), (10000, 10000)]


def run() -> list[BenchResult]:
    big = os.environ.get("BRAKESQUEAL_BENCH_MAP_1E8", "1") != "0"
    res = []
    with tempfile.TemporaryDirectory() as d:
        env = user_env(BRAKESQUEAL_CACHE_DIR=os.path.join(d, "cache"))

        def cli(nx: int, ny: int, *extra: str) -> list[str]:
            return [sys.executable, "-m", "brakesqueal", "map", "--x", f"k_ip=1e5:1e10:{nx}:log",
                    "--y", f"mu=0.05:1:{ny}", "--out", os.path.join(d, "m.nc"), *extra]

        measure(cli(100, 100), env, 1)  # fills the cache (code generation, numba)
        base_t, base_rss, base_load = 0.0, 0.0, 0.0
        runs = [(nx, ny, ()) for nx, ny in SIZES if big or nx * ny < 10**8]
        if big:
            runs += [(10000, 10000, ("--no-eigen",)), (50_000_000, 2, ())]
        for nx, ny, extra in runs:
            load = os.getloadavg()[0]
            t, rss = measure(cli(nx, ny, *extra), env, 1)
            n = nx * ny
            if n == 10**6 and not extra:
                base_t, base_rss, base_load = t, rss, load
            label = (f"brakesqueal map {n:.0e} points ({nx} x {ny})"
                     f"{' --no-eigen' if extra else ' with max_real and frequency'}")
            res.append(BenchResult(f"{label}: peak RSS", rss, "MB", base_rss, rss / base_rss,
                                   {"wall_s": round(t, 3), "cpu_s": round(CPU[-1], 3),
                                    "baseline_wall_s": round(base_t, 3), "load_avg_1min": round(load, 2),
                                    "baseline_load_avg_1min": round(base_load, 2),
                                    "extra_bytes_per_point": (round((rss - base_rss) * 2**20 / (n - 10**6), 2)
                                                              if n > 10**6 else None),
                                    "file_MB": round(os.path.getsize(os.path.join(d, "m.nc")) / 2**20),
                                    "baseline": "the 1e6-point map in the same session",
                                    "target": "1e8 points within 2 GiB (2048 MB)"}))
            os.remove(os.path.join(d, "m.nc"))
    return res


if __name__ == "__main__":
    emit(run())
