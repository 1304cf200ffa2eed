"""Honest progress lines (issue 29, item 6): no early ETA, 100 % once and only when done, monotone fractions."""

from __future__ import annotations

import random
import re

import pytest

from brakesqueal.cli import _progress
from brakesqueal.cli._progress import ETA_MIN_FRACTION, LineReporter, progress

_PCT = re.compile(r": +([0-9.]+)% after")


def _run(fracs: list[float], dts: list[float], every: float = 1.0, done: bool = True) -> list[str]:
    now = [0.0]
    lines: list[str] = []
    rep = LineReporter("simulate", every, clock=lambda: now[0], write=lines.append)
    for f, dt in zip(fracs, dts):
        now[0] += dt
        rep(f)
    if done:
        rep.done()
    return lines


def _check(lines: list[str], done: bool) -> bool:
    pcts = [float(_PCT.search(s).group(1)) for s in lines]
    assert pcts == sorted(pcts), lines  # never lower than before
    assert len(set(lines)) == len(lines) and len(set(pcts)) == len(pcts), lines  # never the same line twice
    hundred = [s for s in lines if "100.0%" in s]
    assert len(hundred) == (1 if done and lines else 0), lines
    if hundred:
        assert lines[-1] is hundred[0]
    for s, p in zip(lines, pcts):
        if "left" in s:
            assert p >= 100 * ETA_MIN_FRACTION and p < 100, s
    return True


@pytest.mark.parametrize("seed", range(40))
def test_random_fractions_jumping_back_and_reaching_one(seed):
    rng = random.Random(seed)
    n = rng.randint(5, 200)
    fracs, f = [], 0.0
    for _ in range(n):
        r = rng.random()
        if r < 0.2:
            f = rng.uniform(0, f)  # jumps back
        elif r < 0.35:
            f = 1.0  # reaches 1.0 (again)
        elif r < 0.4:
            f = rng.choice([float("nan"), -0.5, 1.7])
        else:
            f = min(1.0, f + rng.expovariate(20))
        fracs.append(f)
    dts = [rng.expovariate(1.0) for _ in range(n)]
    done = rng.random() < 0.7
    assert _check(_run(fracs, dts, done=done), done)


def test_stiff_start_gives_no_eta():
    """1 % after 11 s, then done a second later: no "about 1065 s left"."""
    lines = _run([0.01, 0.02, 0.5, 0.999, 1.0, 1.0], [11.0, 0.2, 0.2, 0.2, 0.2, 0.2], every=10.0)
    assert lines and not any("left" in s for s in lines)
    assert _check(lines, True)


def test_repeated_one_prints_hundred_once_at_the_end():
    """A caller reporting 1.0 seven times before 17 s more work: 99.9 % once, then 100 % once when done."""
    lines = _run([1.0] * 7 + [0.3], [2.0] * 7 + [17.0])
    assert sum("100.0%" in s for s in lines) == 1 and lines[-1].split(": ")[2].startswith("100.0%")
    assert sum("99.9%" in s for s in lines) == 1
    assert "after 31 s" in lines[-1]


def test_steady_rate_gives_an_eta_after_ten_percent():
    fracs = [0.02 * k for k in range(1, 40)]
    lines = _run(fracs, [1.0] * len(fracs))
    with_eta = [s for s in lines if "left" in s]
    assert with_eta, lines
    first = float(_PCT.search(with_eta[0]).group(1))
    assert first >= 10.0
    assert "about 30 s left" in [s for s in lines if "40.0%" in s][0]  # 60 % left at 2 %/s
    assert _check(lines, True)


def test_no_hundred_after_an_error(monkeypatch):
    lines: list[str] = []
    now = [0.0]

    class Fake(LineReporter):
        def __init__(self, label, every):
            super().__init__(label, every, clock=lambda: now[0], write=lines.append)

    monkeypatch.setattr(_progress, "LineReporter", Fake)
    monkeypatch.setattr(_progress.sys.stderr, "isatty", lambda: False, raising=False)
    with pytest.raises(RuntimeError), progress("cycles", None, every=1.0) as cb:
        for _ in range(5):
            now[0] += 2.0
            cb(1.0)
        raise RuntimeError
    assert lines == ["brakesqueal: cycles:  99.9% after 2 s"]
    lines.clear()
    with progress("cycles", None, every=1.0) as cb:
        now[0] += 2.0
        cb(0.5)
    assert [s.split(": ")[2][:6] for s in lines] == [" 50.0%", "100.0%"]
