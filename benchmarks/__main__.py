"""``make bench``: run every ``brakesqueal bench`` target and the scripts in ``benchmarks/``.

Each target runs in its own process (so one target's imports and compiled
code do not warm another's) and prints its table; all results are written to
``benchmarks/results.json``.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path


def _targets() -> list[str]:
    from brakesqueal.cli import bench_app

    return [c.name or c.callback.__name__.removeprefix("bench_").replace("_", "-") for c in bench_app.registered_commands]


def main() -> int:
    here = Path(__file__).resolve().parent
    results: dict[str, object] = {}
    for target in _targets():
        print(f"== brakesqueal bench {target}", flush=True)
        proc = subprocess.run(
            [sys.executable, "-m", "brakesqueal", "bench", target, "--format", "json"], capture_output=True, text=True
        )
        if proc.returncode != 0:
            print(proc.stderr, file=sys.stderr)
            return proc.returncode
        data = json.loads(proc.stdout)
        results[target] = data
        for rec in [data, *data.get("more", [])]:
            base = "none" if rec["baseline"] is None else f"{rec['baseline']:.4g}"
            ratio = "" if rec["ratio"] is None else f" ratio {rec['ratio']:.1f}x"
            print(f"  {rec['metric']}: {rec['value']:.4g} {rec['unit']} (baseline {base}){ratio}")
    for script in sorted(here.glob("bench_*.py")):
        print(f"== {script.name}", flush=True)
        proc = subprocess.run([sys.executable, str(script)], text=True)
        if proc.returncode != 0:
            return proc.returncode
    (here / "results.json").write_text(json.dumps(results, indent=2) + "\n")
    print(f"results written to {here / 'results.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
