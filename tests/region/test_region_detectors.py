"""The codimension-2 detectors of the Hopf-curve continuation on a synthetic eigenvalue family with known
generalisations: a zero-Hopf, a double-Hopf and a Bogdanov-Takens point at known places (the linearization is
replaced by the family; the model only supplies the parameter space)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import brakesqueal as bs
from brakesqueal.analysis.maps import Axis
from brakesqueal.region import continue_hopf_curve
from brakesqueal.region import curves as curves_mod

X, Y = Axis("mu", 0.05, 1.0), Axis("Omega", 10.0, 200.0)


def _family(u: np.ndarray) -> np.ndarray:
    """Pair A on the axis along u1 = 0.5 + 0.1 (u0 - 0.5)^2 with omega_A = sqrt(u0 - 0.2) (BT at u0 = 0.2),
    a real eigenvalue u0 - 0.7 (ZH at u0 = 0.7), pair B with real part 0.45 - u0 at 3i (HH at u0 = 0.45)."""
    u0, u1 = float(u[0]), float(u[1])
    a = u1 - 0.5 - 0.1 * (u0 - 0.5) ** 2
    k = u0 - 0.2
    pair_a = [complex(a, math.sqrt(k)), complex(a, -math.sqrt(k))] if k > 0 else \
        [complex(a + math.sqrt(-k)), complex(a - math.sqrt(-k))]
    return np.array([*pair_a, complex(u0 - 0.7), complex(0.45 - u0, 3.0), complex(0.45 - u0, -3.0)])


def _y(u0: float) -> float:
    return Y.start + (0.5 + 0.1 * (u0 - 0.5) ** 2) * (Y.stop - Y.start)


def _x(u0: float) -> float:
    return X.start + u0 * (X.stop - X.start)


def test_zero_hopf_double_hopf_and_bogdanov_takens_are_located(monkeypatch):
    monkeypatch.setattr(curves_mod._Field, "eig", lambda self, u: _family(np.asarray(u, dtype=float)))
    space = bs.resolve_space(preset="paper-fig2", sets={"k_ip": math.inf})
    c = continue_hopf_curve(bs.engine(space), space, X, Y, _x(0.6), _y(0.6), lyapunov=False)
    assert "Bogdanov-Takens" in c.ends and "edge of the box" in c.ends
    found = {s.type: s for s in c.special_points}
    assert set(found) == {"ZH", "HH", "BT"}, c.special_points
    # every point on the curve Re(pair A) = 0
    for p in c.points:
        assert p.y == pytest.approx(_y((p.x - X.start) / (X.stop - X.start)), rel=1e-10)
    assert found["ZH"].x == pytest.approx(_x(0.7), rel=1e-9) and found["ZH"].y == pytest.approx(_y(0.7), rel=1e-9)
    assert found["HH"].x == pytest.approx(_x(0.45), rel=1e-9) and "omega2 = 3" in found["HH"].detail
    assert found["BT"].x == pytest.approx(_x(0.2), abs=1e-5 * (X.stop - X.start))
    assert found["BT"].omega < 0.01


def _bt_normal_form(u: np.ndarray) -> np.ndarray:
    """Eigenvalues of the Bogdanov-Takens normal form x' = y, y' = b1 + b2 x + x^2 + x y at its equilibrium
    through x = 0 (the root of x^2 + b2 x + b1 of smaller modulus), with b2 = u0 - 0.5, b1 = u1 - 0.5: the
    Jacobian [[0, 1], [b2 + 2 x0, x0]]."""
    b2, b1 = float(u[0]) - 0.5, float(u[1]) - 0.5
    disc = b2 * b2 - 4 * b1
    if disc < 0:  # no equilibrium: nothing on the axis
        return np.array([complex(-1.0), complex(-2.0)])
    roots = ((-b2 - math.sqrt(disc)) / 2, (-b2 + math.sqrt(disc)) / 2)
    x0 = min(roots, key=abs)
    return np.linalg.eigvals(np.array([[0.0, 1.0], [b2 + 2 * x0, x0]])).astype(complex)


def test_bogdanov_takens_normal_form_hopf_curve_and_point(monkeypatch):
    """On the Bogdanov-Takens normal form the Hopf curve is b1 = 0 for b2 < 0 with omega = sqrt(-b2), ending at
    the BT point b1 = b2 = 0 (closed forms; beyond it b1 = 0 is a neutral saddle, real eigenvalues +-sqrt(b2)):
    the continuation follows it and locates the end."""
    monkeypatch.setattr(curves_mod._Field, "eig", lambda self, u: _bt_normal_form(np.asarray(u, dtype=float)))
    space = bs.resolve_space(preset="paper-fig2", sets={"k_ip": math.inf})
    y_h = Y.start + 0.5 * (Y.stop - Y.start)  # b1 = 0
    c = continue_hopf_curve(bs.engine(space), space, X, Y, _x(0.2), y_h, lyapunov=False)
    assert "Bogdanov-Takens" in c.ends and "edge of the box" in c.ends
    for p in c.points:
        u0 = (p.x - X.start) / (X.stop - X.start)
        assert p.y == pytest.approx(y_h, rel=1e-10)
        assert p.omega == pytest.approx(math.sqrt(max(0.5 - u0, 0.0)), rel=1e-6, abs=1e-4)
    (bt,) = [s for s in c.special_points if s.type == "BT"]
    assert bt.x == pytest.approx(_x(0.5), abs=1e-5 * (X.stop - X.start))
    assert bt.y == pytest.approx(y_h, rel=1e-10) and bt.omega < 0.01
