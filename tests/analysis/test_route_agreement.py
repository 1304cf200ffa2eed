"""Every applicable verdict route on the same random points: two certified verdicts never contradict.

Route disagreement is how the wrong verdicts of the past arose: each route here is run on its own (not through
the dispatcher's first-that-decides rule) on shared seeded batches of several models — closed forms on grids,
tilted silent motions with pads kept as states, larger models — and for every point the certified codes of all
routes that decided it must agree (a certified "stable" beside a certified "unstable" fails).
"""

from __future__ import annotations

import numpy as np
import pytest

import brakesqueal as bs
from brakesqueal.analysis.verdict import DECIDED, ROUTES, STABLE, UNSTABLE, Context, Points
from brakesqueal.analysis.verdict._linear import operating_points
from brakesqueal.model import resolve_space

CASES = [
    # (model or preset, sets, axis 1, axis 2, grid?)
    ("paper-fig2", (), ("mu", 0.05, 1.0), ("k_ip", 1e5, 1e9), True),
    ("paper-fig3", (), ("mu1", 0.05, 0.95), ("Omega", 1.0, 300.0), True),
    ("paper-fig3", ("h10=0.012",), ("mu1", 0.1, 0.9), ("mu2", 0.1, 0.9), False),  # tilted, pads kept
    ("six-dof", (), ("mu1", 0.1, 1.0), ("k_c", 1e7, 1e10), True),
    ("eight-dof", (), ("k_c", 1e8, 1e10), ("k_cn", 5e6, 5e8), True),
    ("in-plane-pad", (), ("mu", 0.1, 1.0), ("h10", 0.004, 0.016), False),  # tilted without normal dampers
]


def _space(name, sets):
    if name.startswith("paper-"):
        return resolve_space(preset=name, sets=dict(s.split("=") for s in sets))
    return resolve_space(name, None, None, list(sets))


def _route_codes(space, points):
    """Certified codes of every applicable route at every point: ``{route name: (idx, codes)}``."""
    engine = bs.engine(space)
    ctx = Context(engine, space, points, points.size, eigen=True, modes="all")
    ctx.closed = bool(engine.closed_route(space, points.names)) if engine.caps.closed_form else False
    operating_points(ctx)
    pending = np.flatnonzero(np.isin(ctx.status, DECIDED))
    out = {}
    for route in ROUTES:
        if not route.applies(ctx):
            continue
        idx = route.take(ctx, pending)
        if idx.size == 0:
            continue
        res = route.run(ctx, idx)
        alive = np.isin(ctx.status[idx], DECIDED)
        out[route.name] = (idx[alive], res.code[alive], res.max_real[alive])
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name,sets,ax1,ax2,grid", CASES)
def test_routes_never_contradict(name, sets, ax1, ax2, grid):
    import zlib

    rng = np.random.default_rng(zlib.crc32(repr((name, sets)).encode()))
    space = _space(name, sets)
    n1, n2 = (7, 6) if grid else (40, 1)
    lo1, hi1 = ax1[1:]
    lo2, hi2 = ax2[1:]
    log2 = hi2 / lo2 > 100
    v1 = np.sort(rng.uniform(lo1, hi1, n1))
    v2 = np.sort(np.exp(rng.uniform(np.log(lo2), np.log(hi2), n2)) if log2 else rng.uniform(lo2, hi2, n2))
    if grid:
        points = Points.of(space, {ax1[0]: v1, ax2[0]: v2}, grid=True)
    else:
        v2 = np.exp(rng.uniform(np.log(lo2), np.log(hi2), n1)) if log2 else rng.uniform(lo2, hi2, n1)
        points = Points.of(space, {ax1[0]: v1, ax2[0]: v2})
    by_route = _route_codes(space, points)
    assert len(by_route) >= 2, f"{name}: fewer than two routes applied ({list(by_route)})"
    verdicts: dict[int, dict[str, int]] = {}
    for route, (idx, codes, mr) in by_route.items():
        certified = (codes == STABLE) | (codes == UNSTABLE)
        for i, c in zip(idx[certified], codes[certified]):
            verdicts.setdefault(int(i), {})[route] = int(c)
    compared = 0
    for i, vs in verdicts.items():
        assert len(set(vs.values())) == 1, f"{name}: point {i}: routes contradict {vs}"
        compared += len(vs) > 1
    if name == "in-plane-pad":
        # tilted pads without normal dampers: their modes of ~1e20 leave only the extended-precision route certain
        assert sum(len(v) for v in verdicts.values()) > 0, f"{name}: no point certified"
    else:
        assert compared > 0, f"{name}: no point was certified by two routes"
