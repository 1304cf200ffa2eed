"""The command list of ``brakesqueal --help`` gives every command a complete one-line summary."""

from __future__ import annotations

import pytest

import re

import typer.main

from brakesqueal.cli import SUMMARIES, app, main


def test_every_command_has_a_complete_summary(capsys):
    group = typer.main.get_command(app)
    names = set(group.commands)  # type: ignore[attr-defined]
    assert names == set(SUMMARIES), names ^ set(SUMMARIES)
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    listed = out.split("Commands:", 1)[1]
    # joined continuation lines: each summary appears whole, never cut with "..."
    flat = re.sub(r"\s+", " ", listed)
    assert "..." not in flat
    for name, text in SUMMARIES.items():
        assert text.endswith("."), name
        assert re.sub(r"\s+", " ", text) in flat, name


def test_sub_command_summaries_are_whole_sentences(capsys):
    for group in ("cache",):
        assert main([group, "--help"]) == 0
        listed = re.sub(r"\s+", " ", capsys.readouterr().out.split("Commands:", 1)[1])
        assert "..." not in listed and not re.search(r"\bvs\.\s*(\w+\s{2,}|$)", listed), listed


def test_no_arguments_prints_the_help(capsys):
    assert main([]) == 0
    assert "Commands:" in capsys.readouterr().out


@pytest.mark.slow
def test_long_commands_report_progress_on_a_non_terminal(tmp_path):
    """simulate, map, sweep and cycles print one-line progress on a pipe (here every update: the interval set to 0)."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    study = tmp_path / "s.toml"
    study.write_text('preset = "paper-fig2"\n[axes]\nmu = "0.1:1:8"\nk_ip = "1e6:1e9:8:log"\n'
                     '[compute]\nquantities = ["stable"]\n[execution]\nchunk_points = 16\n')
    env = {**os.environ, "BRAKESQUEAL_PROGRESS_EVERY": "0", "MPLBACKEND": "Agg"}
    for label, args in (("simulate", ["simulate", "--t-end", "0.05"]),
                        ("map", ["map", "--x", "k_ip=1e5:1e10:30:log", "--y", "mu=0.05:1:30", "--out", "m.nc"]),
                        ("sweep", ["sweep", str(study), "--out", "s.zarr"]),
                        ("cycles (harmonic balance)", ["cycles", "--preset", "paper-fig3", "--set", "mu1=0.5",
                                                       "--set", "mu2=0.5", "--along", "Omega=30:36.3",
                                                       "--max-points", "8"])):
        r = subprocess.run([sys.executable, "-m", "brakesqueal", *args], cwd=tmp_path, env=env, capture_output=True,
                           text=True, timeout=600)
        assert r.returncode == 0, r.stderr
        lines = [ln for ln in r.stderr.splitlines() if ln.startswith(f"brakesqueal: {label}:")]
        assert lines and "100.0%" in lines[-1], r.stderr
    assert Path(tmp_path / "m.nc").exists()
