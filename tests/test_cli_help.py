"""The command list of ``brakesqueal --help`` gives every command a complete one-line summary."""

from __future__ import annotations

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


def test_no_arguments_prints_the_help(capsys):
    assert main([]) == 0
    assert "Commands:" in capsys.readouterr().out
