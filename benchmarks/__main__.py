"""``make bench``: run every script ``benchmarks/bench_*.py``, each in its own process.

Each script prints its table; scripts that end with one JSON line (the
:mod:`common` convention, or ``--format json`` where a script supports it)
have their results collected into ``benchmarks/results.json``.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path


def main() -> int:
    here = Path(__file__).resolve().parent
    results: dict[str, object] = {}
    for script in sorted(here.glob("bench_*.py")):
        print(f"== {script.name}", flush=True)
        proc = subprocess.run([sys.executable, str(script)], capture_output=True, text=True)
        sys.stdout.write(proc.stdout)
        if proc.returncode != 0:
            print(proc.stderr, file=sys.stderr)
            return proc.returncode
        lines = proc.stdout.strip().splitlines()
        try:
            results[script.stem] = json.loads(lines[-1]) if lines else None
        except json.JSONDecodeError:
            results[script.stem] = None
    (here / "results.json").write_text(json.dumps(results, indent=2) + "\n")
    print(f"results written to {here / 'results.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
