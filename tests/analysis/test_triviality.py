"""One triviality rule for every command (``brakesqueal.status.TRIVIAL_NOISE_FLOOR``).

Before, ``linearize`` called the silent motion trivial when ``mu1 h10 == mu2 h20`` to rounding while
``crossings``/``critical-speed`` wanted the exact rational equality and fell back to a grid search: 21 of 50
float-equal sets got "Omega_crit = UNKNOWN" where an exact answer exists.  Now the path's symbolic residual
is tested to rounding per monomial (:func:`brakesqueal.symbolic.stability_forms.quartic_numerators`), the analogue
of the pointwise rule, and every command takes the exact route on those sets.

The sets are random (seeded): ``h20 = mu1 h10 / mu2`` in floating point, which is almost never the exact rational
equality.  The reference verdicts come from the pointwise evaluator (``evaluate_point``) on either side of every
reported crossing and at the set's own spin, checked against ``linearize``'s verdict there.
"""

from __future__ import annotations

import pytest

from fractions import Fraction

import numpy as np

import brakesqueal as bs
from brakesqueal.model import resolve_space


def _sets(n: int, seed: int) -> list[list[str]]:
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        mu1, mu2 = (float(v) for v in rng.uniform(0.1, 1.0, 2))
        h10 = float(rng.uniform(0.004, 0.016))
        h20 = mu1 * h10 / mu2
        if not 0.002 < h20 < 0.03 or Fraction(mu1) * Fraction(h10) == Fraction(mu2) * Fraction(h20):
            continue  # only sets that are equal in floating point, not exactly
        out.append([f"mu1={mu1!r}", f"mu2={mu2!r}", f"h10={h10!r}", f"h20={h20!r}"])
    return out


def test_float_equal_sets_get_the_same_answer_from_every_command():
    for sets in _sets(12, 11):
        space = resolve_space("paper", None, None, sets)
        lm = bs.linearize(space.resolve({}))
        assert lm.silent.trivial, sets  # the pointwise rule
        cs = bs.critical_speeds(space, 1.0, 1e4)
        assert "exact" in cs.method and cs.complete and cs.Omega_crit_certain, (sets, cs.method)
        path = bs.crossings(space, bs.Axis("k1", 1e5, 1e8, 2, True))
        assert path.exhaustive and "exact" in path.method, sets
        # the reported changes are real: the pointwise verdict flips across each one
        for value, direction in cs.crossings:
            lo = bs.evaluate_point(space, {"Omega": value * (1 - 1e-7)})
            hi = bs.evaluate_point(space, {"Omega": value * (1 + 1e-7)})
            assert lo.decided and hi.decided and lo.stable != hi.stable, (sets, value)
            assert hi.stable == (direction == "stabilizing"), (sets, value, direction)
        # and linearize's verdict at the set's own spin is the one the critical speeds give there
        omega = space.value("Omega")
        before = [c for c in cs.crossings if c[0] < omega]
        expected = before[-1][1] == "stabilizing" if before else cs.stable_at_start
        v = bs.eigen_analysis(lm).verdict()
        assert v.stable == expected, (sets, omega, cs.crossings)


@pytest.mark.slow
def test_sets_off_the_tie_by_more_than_rounding_are_not_trivial():
    """The rule is a rounding tolerance, not a wide one: 1e-9 relative off the tie is a tilted silent motion,
    and the exact route is refused (the numeric route decides, marked not exhaustive)."""
    mu1, mu2, h10 = 0.3, 0.7, 0.014
    h20 = mu1 * h10 / mu2 * (1 + 1e-9)
    space = resolve_space("paper", None, None, [f"mu1={mu1!r}", f"mu2={mu2!r}", f"h10={h10!r}", f"h20={h20!r}"])
    assert not bs.linearize(space.resolve({})).silent.trivial
    r = bs.crossings(space, bs.Axis("k1", 1e5, 1e8, 2, True))
    assert not r.exhaustive and "numeric" in r.method
