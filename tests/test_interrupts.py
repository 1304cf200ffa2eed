"""Ctrl-C in a command-line program ends it within a second, cleanly (issue 11).

Each case runs a small program in a fresh process: an interrupt that cannot be
raised (numba's compiler lock is held, as during a cold compilation) is
answered by the watchdog of :func:`brakesqueal.interrupts.interrupt_guard`
with exit status 130; registered temporary files are removed, critical
sections are waited for, a library guard (no ``exit_after``) never ends the
process.  The programs sleep far longer than the tests' timeouts, so a
missing exit fails the test (no timing assertions).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from brakesqueal.cli import main

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")

PROLOGUE = """
import os, signal, sys, time
from pathlib import Path
from numba.core.compiler_lock import global_compiler_lock
from brakesqueal.interrupts import critical, interrupt_guard, remove_on_exit
tmp = Path(sys.argv[1])
"""


def _run(body: str, tmp_path: Path, timeout: float = 60) -> subprocess.CompletedProcess[str]:
    code = PROLOGUE + textwrap.dedent(body)
    return subprocess.run([sys.executable, "-c", code, str(tmp_path)], capture_output=True, text=True,
                          timeout=timeout)


def test_an_interrupt_during_a_compilation_ends_the_program_and_removes_its_temporary_file(tmp_path):
    out = _run("""
        part = tmp / "out.nc.part"
        part.write_text("half")
        with interrupt_guard(exit_after=0.3), remove_on_exit(part):
            with global_compiler_lock:              # as during a cold numba compilation
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(300)                     # the compilation goes on; the watchdog ends the process
        print("not reached")
    """, tmp_path)
    assert out.returncode == 130, out.stderr
    assert "not reached" not in out.stdout
    assert out.stderr.strip() == "brakesqueal: interrupted"
    assert not (tmp_path / "out.nc.part").exists()


def test_the_exit_waits_for_a_critical_section(tmp_path):
    out = _run("""
        with interrupt_guard(exit_after=0.05):
            with global_compiler_lock:
                with critical():
                    os.kill(os.getpid(), signal.SIGINT)
                    time.sleep(1.0)                 # well beyond exit_after: the exit must wait
                    (tmp / "renamed").write_text("complete")
                time.sleep(300)
    """, tmp_path)
    assert out.returncode == 130, out.stderr
    assert (tmp_path / "renamed").read_text() == "complete"


def test_a_second_interrupt_ends_the_program_at_once(tmp_path):
    out = _run("""
        with interrupt_guard(exit_after=3600):      # the first Ctrl-C alone would wait an hour
            with global_compiler_lock:
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.2)
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(300)
    """, tmp_path, timeout=30)
    assert out.returncode == 130, out.stderr


def test_an_interrupt_outside_a_compilation_is_raised_and_unwinds(tmp_path):
    out = _run("""
        try:
            with interrupt_guard(exit_after=3600):
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(300)
        except KeyboardInterrupt:
            print("unwound")
    """, tmp_path, timeout=30)
    assert out.returncode == 0 and out.stdout.strip() == "unwound", out.stderr


def test_a_library_guard_never_ends_the_process(tmp_path):
    out = _run("""
        try:
            with interrupt_guard():                 # no exit_after: a library call
                with global_compiler_lock:
                    os.kill(os.getpid(), signal.SIGINT)
                    time.sleep(1.0)
                    print("compiled")
        except KeyboardInterrupt:
            print("raised after the compilation")
    """, tmp_path, timeout=30)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["compiled", "raised", "after", "the", "compilation"]


def test_the_program_exits_130_with_one_line_and_the_function_returns_130(tmp_path, capsys, monkeypatch):
    import brakesqueal.cli as cli

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "app", interrupted)
    assert main(["list", "models"]) == 130  # in-process: returned, never os._exit
    assert capsys.readouterr().err.strip() == "brakesqueal: interrupted"
    env = {**os.environ, "MPLBACKEND": "Agg"}
    code = ("import os, signal, sys; from brakesqueal.cli import main; import brakesqueal.cli as c\n"
            "def app(*a, **k):\n    os.kill(os.getpid(), signal.SIGINT)\n    import time; time.sleep(300)\n"
            "c.app = app\nsys.argv = ['brakesqueal', 'list']\nsys.exit(main())\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=30, env=env)
    assert out.returncode == 130 and out.stderr.strip() == "brakesqueal: interrupted", out.stderr


@pytest.mark.skipif(signal.getsignal(signal.SIGINT) is not signal.default_int_handler,
                    reason="the test runner replaced Python's SIGINT handler")
def test_the_guard_restores_the_handler_and_wakeup_fd():
    from brakesqueal.interrupts import interrupt_guard

    before = signal.set_wakeup_fd(-1)
    signal.set_wakeup_fd(before)
    with interrupt_guard(exit_after=10):
        assert signal.getsignal(signal.SIGINT) is not signal.default_int_handler
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    assert signal.set_wakeup_fd(before) == before


def test_main_called_with_arguments_never_ends_its_callers_process(tmp_path):
    """Only the program (``main()`` from the entry point) may end the process; ``main(argv)`` returns 130."""
    code = ("import os, signal, sys, time\nimport brakesqueal.cli as c\n"
            "from numba.core.compiler_lock import global_compiler_lock\n"
            "def app(*a, **k):\n    with global_compiler_lock:\n        os.kill(os.getpid(), signal.SIGINT)\n"
            "        time.sleep(1.5)\n    from brakesqueal.interrupts import check_interrupt\n    check_interrupt()\n"
            "c.app = app\nprint('returned', c.main(['list']))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.strip() == "returned 130", (out.stdout, out.stderr)
