"""One rule for every output path of every command (issue 11): the directory that holds it must exist.

A file (``--out``, ``--plot``, ``--wav``), an output directory (``reproduce
--out``) or a sweep store (``sweep --out``) in a directory that does not
exist is refused before anything is computed: one line naming the option's
path and the missing directory, exit status 2, and nothing created.
"""

from __future__ import annotations

import pytest

from brakesqueal.cli import main

PAPER = ["--set", "mu=0.5"]
COMMANDS = {
    "map --out": ["map", "--x", "k_ip=1e5:1e10:4:log", "--y", "mu=0.05:1:4", "--out", "{p}.nc"],
    "map --plot": ["map", "--x", "k_ip=1e5:1e10:4:log", "--y", "mu=0.05:1:4", "--out", "ok.nc", "--plot", "{p}.png"],
    "crossings --plot": ["crossings", "--along", "k_ip=1e5:1e10:log", *PAPER, "--plot", "{p}.png"],
    "critical-speed --plot": ["critical-speed", "--preset", "paper-fig3", "--plot", "{p}.png"],
    "cycles --out": ["cycles", "--along", "k_ip=1e5:1e10:log", *PAPER, "--out", "{p}.nc"],
    "cycles --plot": ["cycles", "--along", "k_ip=1e5:1e10:log", *PAPER, "--plot", "{p}.png"],
    "modes --out": ["modes", "--along", "k_ip=1e5:1e10:log", "--out", "{p}.nc"],
    "modes --plot": ["modes", "--along", "k_ip=1e5:1e10:log", "--plot", "{p}.png"],
    "simulate --out": ["simulate", "--out", "{p}.nc"],
    "simulate --plot": ["simulate", "--plot", "{p}.png"],
    "simulate --wav": ["simulate", "--wav", "{p}.wav"],
    "export --out": ["export", "--to", "c", "--out", "{p}.c"],
    "reproduce --out": ["reproduce", "fig2", "--out", "{p}"],
    "sweep --out": ["sweep", "{study}", "--out", "{p}.zarr"],
}


@pytest.mark.parametrize("case", sorted(COMMANDS))
def test_an_output_in_a_missing_directory_is_refused_in_one_line(tmp_path, monkeypatch, capsys, case):
    monkeypatch.chdir(tmp_path)
    study = tmp_path / "study.toml"
    study.write_text('preset = "paper-fig2"\n[axes]\nmu = "0.1:1:3"\nk_ip = "1e6:1e8:2"\n')
    before = sorted(p.name for p in tmp_path.iterdir())
    missing = tmp_path / "no" / "such"
    args = [a.format(p=missing / "x", study=study) for a in COMMANDS[case]]
    assert main(args) == 2
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert len(err) == 1 and "does not exist" in err[0] and str(missing) in err[0], err
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # nothing created, nothing computed


@pytest.mark.parametrize("case", ["reproduce --out", "sweep --out"])
def test_an_output_directory_itself_is_created(tmp_path, monkeypatch, case):
    from brakesqueal.outputs import check_output_dir
    from brakesqueal.sweep.store import check_location

    d = tmp_path / "new"
    if case == "reproduce --out":
        assert check_output_dir(d, what="--out") == d and d.is_dir()
    else:
        check_location(tmp_path / "s.zarr")  # its parent exists: accepted (the store is made by the sweep)
        assert not (tmp_path / "s.zarr").exists()
