"""The shipped closed forms of ``brakesqueal derive`` equal the live derivation, byte for byte.

``brakesqueal.cli._closed_forms`` is generated (``python -m brakesqueal.cli.closed_forms --write``); when one of
these tests fails after an edit of the derivation, regenerate it and review the diff.
"""

from __future__ import annotations

import itertools
import shutil

import pytest

from brakesqueal.cli import _closed_forms as data
from brakesqueal import fingerprint
from brakesqueal.cli import closed_forms, main
from brakesqueal.render import render_closed_form

PAIRS = list(itertools.product(closed_forms.CASES, closed_forms.FORMATS))
REGENERATE = "stale shipped closed forms: run `python -m brakesqueal.cli.closed_forms --write` and review the diff"


def test_every_case_and_format_is_shipped():
    from brakesqueal.cli import Case, DeriveFormat

    assert set(closed_forms.CASES) == {c.value for c in Case}
    assert set(closed_forms.FORMATS) == {f.value for f in DeriveFormat}
    assert set(data.TEXTS) == set(PAIRS)


@pytest.mark.parametrize("case, fmt", PAIRS)
def test_shipped_text_is_the_live_derivation(case, fmt):
    """Derived here, in this process, from the symbolic model."""
    shipped = closed_forms.shipped_text(case, fmt)
    assert shipped is not None, REGENERATE
    assert shipped == render_closed_form(case, fmt), REGENERATE


def test_generated_module_is_current():
    """Regenerating (live derivation in a fresh interpreter, its import closure, the fingerprint) changes nothing."""
    assert closed_forms.data_source() == closed_forms._DATA.read_text(encoding="utf-8"), REGENERATE


def test_sources_are_the_code_generating_modules_the_derivation_imports():
    from brakesqueal.codegen import cache

    sources = closed_forms.derivation_sources()
    assert sources == data.SOURCES, REGENERATE
    assert {"render.py", "symbolic/linearize.py", "symbolic/model.py"} <= set(sources)
    listed = {p.relative_to(closed_forms._PKG).as_posix() for p in cache.generator_files()}
    assert set(sources) <= listed


def test_fingerprint_follows_every_source(tmp_path, monkeypatch):
    """A changed or missing source file, or another SymPy version, gives another fingerprint."""
    for rel in data.SOURCES:
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(closed_forms._PKG / rel, tmp_path / rel)
    monkeypatch.setattr(closed_forms, "_PKG", tmp_path)
    assert closed_forms.fingerprint(data.SOURCES) == data.FINGERPRINT
    seen = {data.FINGERPRINT}
    for rel in data.SOURCES:
        p = tmp_path / rel
        original = p.read_bytes()
        p.write_bytes(original + b"\n")
        seen.add(closed_forms.fingerprint(data.SOURCES))
        p.unlink()
        seen.add(closed_forms.fingerprint(data.SOURCES))
        p.write_bytes(original)
    assert len(seen) == 1 + 2 * len(data.SOURCES)
    crlf = tmp_path / data.SOURCES[0]
    original = crlf.read_bytes()
    crlf.write_bytes(original.replace(b"\n", b"\r\n"))  # a CRLF checkout of the same source
    assert closed_forms.fingerprint(data.SOURCES) == data.FINGERPRINT
    crlf.write_bytes(original)
    assert closed_forms.shipped_text("general", "text") is not None
    monkeypatch.setattr(fingerprint, "EXTERNAL", (("sympy", "__init__.py"), ("symengine", "_version.py")))
    assert closed_forms.shipped_text("general", "text") is None


@pytest.mark.parametrize("case, fmt", PAIRS)
def test_derive_fast_path_prints_the_full_derivation(case, fmt, capsys, tmp_path, monkeypatch):
    """``derive`` (shipped text, nothing cached) prints what ``derive --no-cache`` (live derivation) prints."""
    monkeypatch.setenv("BRAKESQUEAL_CACHE_DIR", str(tmp_path / "cache"))
    assert main(["derive", "--case", case, "--format", fmt]) == 0
    fast = capsys.readouterr().out
    assert not (tmp_path / "cache").exists()  # the shipped text needs no cache
    assert main(["derive", "--case", case, "--format", fmt, "--no-cache"]) == 0
    assert capsys.readouterr().out == fast
    assert fast == render_closed_form(case, fmt).rstrip("\n") + "\n"


def test_stale_shipped_text_falls_back_to_the_derivation_and_its_cache(capsys, tmp_path, monkeypatch):
    monkeypatch.setenv("BRAKESQUEAL_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(data, "FINGERPRINT", "0" * 64)
    assert closed_forms.shipped_text("symmetric", "latex") is None
    assert main(["derive", "--case", "symmetric", "--format", "latex"]) == 0
    assert capsys.readouterr().out == data.TEXTS["symmetric", "latex"] + "\n"
    entries = list(tmp_path.glob("*/closed-forms/symmetric.latex"))
    assert len(entries) == 1  # derived and cached as before the shipped texts
    assert main(["derive", "--case", "symmetric", "--format", "latex"]) == 0
    assert capsys.readouterr().out == data.TEXTS["symmetric", "latex"] + "\n"
