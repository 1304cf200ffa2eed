"""Certified robust design windows (issue 27, item 4): ``brakesqueal robust`` and :mod:`brakesqueal.robust`.

The paper's Fig. 2 (preset ``paper-fig2``): on ``mu = 0.5`` the stability of the silent motion changes at
``k_ip = 2.308813e5`` and ``1.866013e6`` N/m (stable between).  Boxes straddling those values must never come
out stable; boxes well inside the stable window must come out stable; the enclosures behind every decision are
checked against exact rational evaluation at random points of random boxes.
"""

from __future__ import annotations

import json
from fractions import Fraction

import numpy as np
import pytest

import brakesqueal
from brakesqueal.analysis.verdict import UNSTABLE
from brakesqueal.cli import main
from brakesqueal.errors import ParameterError
from brakesqueal.model.parameters import ParameterSpace
from brakesqueal.robust import decide_boxes, parse_box, robust_box, stable_margins

K_LOW, K_HIGH = 2.308813e5, 1.866013e6


@pytest.fixture(scope="module")
def fig2():
    space = ParameterSpace.from_preset("paper-fig2")
    return brakesqueal.engine(space), space


def cli(capsys, *args: str) -> tuple[int, str, str]:
    rc = main(list(args))
    out = capsys.readouterr()
    return rc, out.out, out.err


# ---------------------------------------------------------------- decisions near and away from the boundary
@pytest.mark.parametrize("k", [K_LOW, K_HIGH])
@pytest.mark.parametrize("rel", [1e-1, 1e-3, 1e-5])
def test_boxes_straddling_the_fig2_boundary_are_never_stable(fig2, k, rel):
    eng, space = fig2
    r = robust_box(eng, space, {"mu": (0.5 - 1e-7, 0.5 + 1e-7), "k_ip": (k * (1 - rel), k * (1 + rel))})
    assert r.verdict in ("unstable", "undecided"), r
    if r.verdict == "unstable":
        assert r.witness is not None and r.witness_max_real is not None and r.witness_max_real >= 0
        assert k * (1 - rel) <= r.witness["k_ip"] <= k * (1 + rel)
        pv = brakesqueal.evaluate_point(space, r.witness)
        assert pv.method != "none" and not pv.stable, pv


def test_straddling_boxes_find_a_witness_in_a_thin_unstable_sliver(fig2):
    """k_ip in [230880, 1.866e6] on mu = 0.5 is unstable only on [230880, 230881.3]: the witness is there."""
    eng, space = fig2
    r = robust_box(eng, space, {"mu": (0.5, 0.5000001), "k_ip": (230880.0, 1.866e6)})
    assert r.verdict == "unstable" and r.witness is not None
    assert 230880.0 <= r.witness["k_ip"] <= K_LOW
    same = robust_box(eng, space, {"mu": (0.5, 0.5000001), "k_ip": (230890.0, 1.866e6)})
    assert same.verdict == "stable", same


@pytest.mark.parametrize("box", [
    {"mu": (0.45, 0.5), "k_ip": (3e5, 1.5e6)},
    {"mu": (0.4, 0.5), "k_ip": (4e5, 1.2e6)},
    {"mu": (0.499, 0.501), "k_ip": (2.4e5, 1.8e6)},
    {"k_ip": (2.4e5, 1.85e6)},
])
def test_boxes_inside_the_stable_window_are_stable(fig2, box):
    eng, space = fig2
    r = robust_box(eng, space, box)
    assert r.verdict == "stable", r
    assert r.witness is None and r.undecided_boxes == [] and r.stable_boxes >= 1


def test_boxes_in_the_unstable_region_have_a_certified_witness(fig2):
    eng, space = fig2
    r = robust_box(eng, space, {"mu": (0.49, 0.51), "k_ip": (5e6, 2e7)})
    assert r.verdict == "unstable" and r.witness is not None
    assert r.witness_max_real is not None and r.witness_max_real > 0


def test_an_exhausted_budget_is_undecided_with_its_sub_boxes(fig2):
    """A box whose unstable part is a sliver of relative width 1e-9 needs more than 3 sub-boxes: undecided."""
    eng, space = fig2
    r = robust_box(eng, space, {"mu": (0.5, 0.5000001), "k_ip": (K_LOW * (1 - 1e-9), 1.8e6)}, max_boxes=3)
    assert r.verdict == "undecided"
    assert r.undecided_boxes and all(set(b) == {"mu", "k_ip"} for b in r.undecided_boxes)


# ---------------------------------------------------------------- enclosures: exact arithmetic at random points
def test_enclosures_contain_the_exact_values_at_random_points(fig2, rng):
    from brakesqueal.robust._enclose import enclose
    from brakesqueal.robust._table import poly_table

    eng, space = fig2
    tab = poly_table(eng, space, ("mu", "k_ip"))
    assert tab is not None
    n = 60
    c = np.stack([rng.uniform(0.1, 1.0, n), 10 ** rng.uniform(5, 7, n)], axis=1)
    w = 10 ** rng.uniform(-6, -0.5, (n, 2))
    lo, hi = c * (1 - w), c * (1 + w)
    low, high, mid, mlow, mhigh, _ = enclose(tab, lo, hi)
    exps = [tuple(int(v) for v in e) for e in np.argwhere(np.ones(tab.coef.shape[1:], dtype=bool))]
    for i in range(n):
        for t in [mid[i], lo[i], hi[i], lo[i] + rng.uniform(0, 1, 2) * (hi[i] - lo[i])]:
            x = [Fraction(float(v)) for v in np.clip(t, lo[i], hi[i])]
            for p in range(tab.coef.shape[0]):
                val = sum(Fraction(float(tab.coef[(p, *e)])) * x[0] ** e[0] * x[1] ** e[1] for e in exps)
                slack = sum(Fraction(float(tab.rad[(p, *e)])) * abs(x[0] ** e[0] * x[1] ** e[1]) for e in exps)
                assert Fraction(float(low[i, p])) <= val - slack and val + slack <= Fraction(float(high[i, p]))
            if t is mid[i]:
                for p in range(tab.coef.shape[0]):
                    val = sum(Fraction(float(tab.coef[(p, *e)])) * x[0] ** e[0] * x[1] ** e[1] for e in exps)
                    assert Fraction(float(mlow[i, p])) <= val <= Fraction(float(mhigh[i, p]))


def test_the_table_matches_the_exact_quartic(fig2):
    """The Taylor coefficients' polynomials are the exact numerators: compare with the exact point route."""
    from brakesqueal.analysis.robust import exact_trivial_entries, routh_exact
    from brakesqueal.robust._table import poly_table

    eng, space = fig2
    tab = poly_table(eng, space, ("mu", "k_ip"))
    assert tab is not None
    for mu, k in [(0.5, 1e6), (0.3, 2e5), (0.9, 5e6), (0.5, 2.3e5)]:
        e = exact_trivial_entries(eng, space.resolve({"mu": mu, "k_ip": k}).vector())
        m11, m12, m21, m22, d11, d12, d21, d22, k11, k12, k21, k22 = e
        a = [k11 * k22 - k12 * k21, d11 * k22 + k11 * d22 - d12 * k21 - k12 * d21,
             m11 * k22 + d11 * d22 + k11 * m22 - m12 * k21 - d12 * d21 - k12 * m21,
             m11 * d22 + d11 * m22 - m12 * d21 - d12 * m21, m11 * m22 - m12 * m21]
        x = (Fraction(mu), Fraction(k))
        exps = [tuple(int(v) for v in q) for q in np.argwhere(np.ones(tab.coef.shape[1:], dtype=bool))]
        vals = [sum(Fraction(float(tab.coef[(p, *q)])) * x[0] ** q[0] * x[1] ** q[1] for q in exps)
                for p in range(7)]
        den, N = vals[0], vals[1:6]
        for i in range(5):  # N_i = Den a_i (to the table's outward rounding, relatively tiny)
            assert abs(N[i] - den * a[i]) <= Fraction(1, 10 ** 12) * abs(den * a[i]) + Fraction(1, 10 ** 300)
        assert routh_exact(N) == routh_exact(a)


# ---------------------------------------------------------------- many boxes, margins
def test_decide_boxes_agrees_with_robust_box(fig2, rng):
    eng, space = fig2
    n = 40
    c = np.stack([rng.uniform(0.2, 0.9, n), 10 ** rng.uniform(5, 7, n)], axis=1)
    w = 10 ** rng.uniform(-3, -1, (n, 2))
    v = decide_boxes(eng, space, ["mu", "k_ip"], c * (1 - w), c * (1 + w))
    for i in range(0, n, 7):
        r = robust_box(eng, space, {"mu": (c[i, 0] * (1 - w[i, 0]), c[i, 0] * (1 + w[i, 0])),
                                    "k_ip": (c[i, 1] * (1 - w[i, 1]), c[i, 1] * (1 + w[i, 1]))}, max_boxes=400)
        assert r.verdict == v.verdicts[i]


def test_margins_are_certified_and_close_to_the_fig2_crossings(fig2):
    eng, space = fig2
    nominal = space.with_values({"mu": 0.5, "k_ip": 1e6})
    m = stable_margins(eng, nominal, ["k_ip"], within={"k_ip": (1e5, 1e7)})
    lo, hi = m.windows["k_ip"]
    assert K_LOW < lo < K_LOW * 1.01 and K_HIGH * 0.99 < hi < K_HIGH
    assert robust_box(eng, nominal, {"k_ip": (lo, hi)}).verdict == "stable"
    two = stable_margins(eng, nominal, ["mu", "k_ip"], within={"mu": (0.05, 1.0), "k_ip": (1e5, 1e7)})
    assert 0 < two.scale <= 1
    assert robust_box(eng, nominal, two.box).verdict == "stable"
    assert two.box["mu"][0] <= 0.5 <= two.box["mu"][1]


def test_margins_refuse_an_unstable_nominal_design(fig2):
    eng, space = fig2
    with pytest.raises(ParameterError, match="not certified stable"):
        stable_margins(eng, space.with_values({"mu": 0.5, "k_ip": 1e7}), ["k_ip"])


# ---------------------------------------------------------------- CLI
def test_cli_exact_form_json(capsys):
    rc, out, err = cli(capsys, "robust", "--box", "mu=0.35:0.55", "--box", "k_ip=2e5:2e6", "--format", "json")
    assert rc == 0, err
    d = json.loads(out)
    assert d["verdict"] == "unstable" and d["method"].startswith("branch-and-bound")
    assert set(d["witness"]) == {"mu", "k_ip", "max_real", "frequency"} and d["witness"]["max_real"] > 0
    assert 0.35 <= d["witness"]["mu"] <= 0.55 and 2e5 <= d["witness"]["k_ip"] <= 2e6
    assert d["undecided_boxes"] == [] and d["boxes_examined"] >= 1
    rc, out, err = cli(capsys, "robust", "--preset", "paper-fig2", "--box", "mu=0.4:0.5", "--box",
                       "k_ip=4e5:1.2e6", "--format", "json")
    assert rc == 0, err
    d = json.loads(out)
    assert d["verdict"] == "stable" and d["witness"] is None and d["stable_boxes"] >= 1


def test_cli_text_and_margins(capsys):
    rc, out, err = cli(capsys, "robust", "--box", "k_ip=1e5:1e7", "--set", "mu=0.5", "--set", "k_ip=1e6",
                       "--margins")
    assert rc == 0, err
    assert "verdict: unstable somewhere" in out and "margins around" in out and "largest stable box" in out


@pytest.mark.parametrize("args, names", [
    (["--box", "mu=0.5:0.5"], ["degenerate", "mu"]),
    (["--box", "mu=0.55:0.35"], ["reversed", "mu"]),
    (["--box", "muu=0.3:0.5"], ["unknown", "muu"]),
    (["--box", "mu1=0.3:0.5"], ["tied", "mu1"]),
    (["--box", "mu=0.3:0.5", "--box", "mu=0.3:0.6"], ["twice", "mu"]),
    (["--box", "mu=0.3"], ["NAME=LO:HI"]),
    (["--box", "mu=0.3:inf"], ["finite", "mu"]),
    (["--box", "mu=-0.3:0.5"], ["invalid", "mu"]),
    (["--box", "mu1=0.3:0.5", "--model", "six-dof"], ["six-dof", "closed-form"]),
    (["--box", "mu1=0.3:0.5", "--preset", "paper-fig3", "--set", "h10=0.012"], ["silent motion", "mu1"]),
])
def test_cli_bad_input_is_one_line(capsys, args, names):
    rc, out, err = cli(capsys, "robust", *args)
    assert rc == 2, (out, err)
    lines = [ln for ln in err.strip().splitlines() if not ln.startswith("brakesqueal: note:")]
    assert len(lines) == 1 and lines[0].startswith("brakesqueal: error: ") and "Traceback" not in err, err
    for n in names:
        assert n in lines[0], lines[0]


def test_library_bad_input(fig2):
    eng, space = fig2
    with pytest.raises(ParameterError, match="degenerate"):
        robust_box(eng, space, {"mu": (0.5, 0.5)})
    with pytest.raises(ParameterError, match="reversed"):
        parse_box("k_ip=2e6:2e5")
    with pytest.raises(ParameterError, match="shape"):
        decide_boxes(eng, space, ["mu"], [[0.1, 0.2]], [[0.3]])
    other = ParameterSpace.from_preset("six-dof")
    with pytest.raises(ParameterError, match="engine is of model"):
        robust_box(eng, other, {"mu1": (0.3, 0.5)})


def test_witnesses_are_confirmed_by_the_dispatcher(fig2, rng):
    eng, space = fig2
    n = 30
    c = np.stack([rng.uniform(0.5, 0.9, n), 10 ** rng.uniform(6.5, 7, n)], axis=1)
    v = decide_boxes(eng, space, ["mu", "k_ip"], c * 0.99, c * 1.01)
    wit = v.code == 0
    assert wit.any()
    chk = brakesqueal.evaluate(space, {"mu": v.witness[wit, 0], "k_ip": v.witness[wit, 1]})
    assert np.all(np.asarray(chk.code) == UNSTABLE)


# ---------------------------------------------------------------- worst case
@pytest.mark.parametrize("box", [{"mu": (0.4, 0.5), "k_ip": (4e5, 1.2e6)}, {"mu": (0.45, 0.55), "k_ip": (1e6, 3e6)}])
def test_worst_case_bounds_every_sample(fig2, rng, box):
    from brakesqueal.robust import worst_case

    eng, space = fig2
    w = worst_case(eng, space, box)
    assert w.lower <= w.upper and w.upper - w.lower <= 1e-6 * max(1.0, abs(w.lower))
    n = 20000
    pts = {k: rng.uniform(a, b, n) for k, (a, b) in box.items()}
    mr = np.asarray(brakesqueal.evaluate(space, pts).max_real)
    assert np.nanmax(mr) < w.upper
    r = robust_box(eng, space, box)
    assert (r.verdict == "stable") == (w.upper <= 0)
    assert all(box[k][0] <= v <= box[k][1] for k, v in w.at.items())


def test_cli_worst_case(capsys):
    rc, out, err = cli(capsys, "robust", "--box", "mu=0.4:0.5", "--box", "k_ip=4e5:1.2e6", "--worst-case",
                       "--format", "json")
    assert rc == 0, err
    d = json.loads(out)
    assert d["verdict"] == "stable" and d["worst_max_real"]["upper"] < 0
    assert d["worst_max_real"]["lower"] <= d["worst_max_real"]["upper"]
