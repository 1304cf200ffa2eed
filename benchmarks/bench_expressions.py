"""``modes_along`` on the paper model with and without the cache of parsed tie expressions.

Both runs in this process: the baseline replaces the cached parse by the plain one
(``expressions._checked_tree``), which is what ``Preset.resolve`` did at every point before.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import BenchResult, best_time, emit  # noqa: E402

from brakesqueal import modes_along  # noqa: E402
from brakesqueal.model import expressions, resolve_space  # noqa: E402


def main() -> None:
    space = resolve_space(preset="paper-fig3", sets=["mu1=0.5", "mu2=0.5"])

    def run() -> None:
        modes_along(space, "Omega", 1.0, 1000.0, num=200, log=True)

    run()
    cached = best_time(run, repeat=5)
    original = expressions._checked_tree
    expressions._checked_tree = expressions._parse_and_check  # type: ignore[assignment]
    try:
        plain = best_time(run, repeat=5)
    finally:
        expressions._checked_tree = original
    emit([BenchResult("modes_along paper-fig3, 200 Omega values, cached tie trees", cached, "s",
                      baseline=plain, ratio=plain / cached,
                      details={"baseline": "the same call re-parsing every tie at every point"})])


if __name__ == "__main__":
    main()
