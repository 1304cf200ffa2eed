"""Ctrl-C while numba compiles is recorded, not raised inside the compiler, and raised at the next safe point.

(An interrupt unwound through llvmlite's callbacks could abort the process on an LLVM assertion, seen in
about 1 of 30 cold-cache trials of ``brakesqueal simulate``.)
"""

from __future__ import annotations

import os
import signal
import time

import pytest

from brakesqueal.interrupts import check_interrupt, interrupt_guard


@pytest.mark.skipif(signal.getsignal(signal.SIGINT) is not signal.default_int_handler,
                    reason="the test runner replaced Python's SIGINT handler")
def test_interrupt_during_compilation_is_deferred_to_a_safe_point():
    from numba.core.compiler_lock import global_compiler_lock

    reached = []
    with pytest.raises(KeyboardInterrupt):
        with interrupt_guard():
            with global_compiler_lock:  # as during a compilation
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.05)  # the handler runs here: it must not raise inside the "compiler"
                reached.append("compiled")
            reached.append("after")
            check_interrupt()  # the safe point after the compilation raises it
    assert reached == ["compiled", "after"]
    # outside a compilation the interrupt is raised at once, as before
    with pytest.raises(KeyboardInterrupt):
        with interrupt_guard():
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.05)
            pytest.fail("the interrupt was not raised")
