"""``make demo``: the main job of the toolkit on a fresh machine.

Prints the closed-form linear matrices of the paper's cases, linearizes the
paper's presets, and (when the stability module is present) reproduces the
paper's Figures 2 and 3 into ``results/``.
"""

from __future__ import annotations

import sys

from .cli import main as cli


def _section(title: str) -> None:
    print(f"\n{'=' * 78}\n{title}\n{'=' * 78}", flush=True)


def main() -> int:
    """Run the demo; returns the exit status."""
    for case in ("symmetric", "asymmetric-friction", "minimal"):
        _section(f"brakesqueal derive --case {case}")
        if rc := cli(["derive", "--case", case]):
            return rc
    for preset in ("paper-fig2", "paper-fig3"):
        _section(f"brakesqueal linearize --preset {preset}")
        if rc := cli(["linearize", "--preset", preset]):
            return rc
    _section("brakesqueal linearize --preset paper-fig3 --set mu1=0.7 --set mu2=0.3 --format json")
    if rc := cli(["linearize", "--preset", "paper-fig3", "--set", "mu1=0.7", "--set", "mu2=0.3", "--format", "json"]):
        return rc
    from .cli import app

    if any(c.name == "reproduce" for c in app.registered_commands):
        _section("brakesqueal reproduce all --out results/")
        if rc := cli(["reproduce", "all", "--out", "results"]):
            return rc
    return 0


if __name__ == "__main__":
    sys.exit(main())
