"""How much a tangential pad damper ``d_ip`` changes the paper's model, and why it keeps the pads' rates defined.

Reproduces the numbers quoted in ``docs/simulation.md`` (section "Pads with a tangential damper"), on paper-fig3
with ``mu1 = mu2 = 0.5`` and ``k_ip = 1e6``:

1. the leading eigenvalue at ``Omega = 120`` rad/s with and without the damper (``d_ip`` = 1, 10, 100 N s/m):
   its move relative to its modulus and the growth rate's relative change;
2. the onset (first destabilizing crossing along ``Omega``) without and with ``d_ip = 10``;
3. the slope ``k_ip dG/dldot`` of each pad's balance along a unilateral run at ``Omega = 160`` rad/s with
   ``d_ip = 1`` N s/m, computed from the *symbolic* balance ``G`` (SymPy, ``build_equations``), not from the
   compiled kernels: its range over the run relative to ``d_ip``, and its smallest value while ``F_n < 200`` N.

Run: ``.venv/bin/python examples/pad_damper_numbers.py`` (about a minute with warm caches).
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from brakesqueal import Axis, ParameterSpace, build_equations, crossings, linearize, simulate
from brakesqueal.model.options import damped_pads

BASE = {"mu1": 0.5, "mu2": 0.5, "k_ip": 1e6}


def leading(space: ParameterSpace, omega: float) -> complex:
    """The eigenvalue with the largest real part (positive imaginary part) at ``Omega = omega``."""
    lam = np.asarray(linearize(space.resolve({"Omega": omega})).eigenvalues, dtype=complex)
    lam = lam[lam.imag > 0]
    return complex(lam[np.argmax(lam.real)])


def eigenvalue_shifts() -> None:
    base = ParameterSpace.from_preset("paper-fig3", BASE)
    lam0 = leading(base, 120.0)
    print(f"1. leading eigenvalue at Omega = 120 rad/s, no damper: {lam0:.8g}")
    for d in (1.0, 10.0, 100.0):
        lam = leading(damped_pads(base, d), 120.0)
        print(f"   d_ip = {d:5g} N s/m: {lam:.8g}; moved {abs(lam - lam0) / abs(lam0):.2g} of |lambda|, "
              f"growth rate {100 * (lam.real / lam0.real - 1):+.3g} %")


def onsets() -> None:
    base = ParameterSpace.from_preset("paper-fig3", BASE)
    axis = Axis("Omega", 30.0, 120.0)
    for label, space in (("no damper", base), ("d_ip = 10", damped_pads(base, 10.0))):
        r = crossings(space, axis)
        first = next(v for v, direction in r.crossings if direction == "destabilizing")  # type: ignore[attr-defined]
        print(f"2. onset, {label}: Omega = {first:.4f} rad/s")


def balance_slope(d_ip: float = 1.0, omega: float = 160.0, t_end: float = 0.3) -> None:
    space = damped_pads(ParameterSpace.from_preset("paper-fig3", BASE), d_ip)
    params = space.resolve({"Omega": omega})
    spec = params.model
    chi = {p.name: sp.Symbol(f"chi_{p.name}") for p in spec.pads}
    eq = build_equations(spec, "sympy", engagement=chi)
    stiff = set(spec.stiffness_names())
    values = []
    for name in spec.parameters:
        v = float(params[name])
        values.append((0.0 if math.isinf(v) else 1.0 / v) if name in stiff else v)
    psub = dict(zip(eq.params, values))
    args = [*eq.Q, *eq.dQ, *eq.L, *eq.dL, *chi.values()]
    dG = [sp.lambdify(args, sp.diff(g, dl).subs(psub), "numpy") for g, dl in zip(eq.G, eq.dL)]
    tr = simulate(params, t_end, perturbation=[1e-2, 0.0], contact="unilateral", events="continue")
    n = len(eq.Q)
    Fn = tr.contact[:, :, 0]
    k = spec.pads[0].k_ip  # both pads: k_ip = 1e6
    k_ip = float(params[k]) if isinstance(k, str) else float(k)
    slopes = []
    for i in range(tr.t.size):
        eng = list(map(float, tr.engaged[i])) if tr.engaged is not None else [float(f > 0) for f in Fn[i]]
        row = [*tr.y[i, :n], *tr.y[i, n:2 * n], *tr.l[i], *tr.l_rates[i], *eng]
        slopes.append([k_ip * float(f(*row)) for f in dG])
    s = np.array(slopes) / d_ip
    low = s[Fn < 200.0]
    print(f"3. k_ip dG/dldot / d_ip along {tr.t.size} samples ({tr.status}, {t_end} s at Omega = {omega}): "
          f"{s.min():.4g} .. {s.max():.4g}; for F_n < 200 N: min {low.min() if low.size else float('nan'):.6g}")


if __name__ == "__main__":
    eigenvalue_shifts()
    onsets()
    balance_slope()
