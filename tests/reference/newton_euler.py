"""Independent reference implementation of the wobbling-disk brake-squeal model.

This module is a *second formalism* used only to cross-check the package
``brakesqueal``.  It deliberately does not import anything from the package and
does not use the paper's matrix formulas (rotational Jacobians/Hessians,
Kronecker products).  Instead the model is derived with vectors and dyadics of
``sympy.physics.mechanics``:

1. Kinematics.  ``B = N.orientnew('B', 'Body', [q1, q2, q3], 'XYZ')`` (Cardan
   angles: x0, then y1, then z2).  The angular velocity ``w = B.ang_vel_in(N)``
   is taken from sympy, the intermediate frame ``A1`` (rotation q1 about x0)
   provides the support axis y1.
2. Contact points.  ``p_i = p_li + h_i z0`` with ``p_l1 = (l1, -r, -h10)``,
   ``p_l2 = (l2, -r, +h20)`` in N; ``h_i`` follows from ``p_i`` lying in the
   disk face ``(p_i - K_i) . z_B = 0`` with ``K_1 = -h10 z_B``,
   ``K_2 = +h20 z_B``, i.e. ``h_i = -(p_li . z_B -/+ h_i0) / (z0 . z_B)``.
3. Sliding velocity.  ``v_ri = d/dt|_N p_i - v_Di`` where ``D_i`` is the disk
   material point coincident with ``p_i`` (``v2pt_theory``, = ``w x p_i``).
   ``t_i = v_ri / |v_ri|``.
4. Contact forces on the disk ``f_1 = Fn1 (z_B + mu1 t_1)``,
   ``f_2 = Fn2 (-z_B + mu2 t_2)``; the normal forces come from the z0 force
   balance of the massless pads (spring/damper force on the pad + reaction
   ``-f_i`` = 0)::

       Fn1 = (N0 - k1 h1 - d1 dh1) / (z0.z_B + mu1 z0.t_1)
       Fn2 = (N0 + k2 h2 + d2 dh2) / (z0.z_B - mu2 z0.t_2)

   The x0 force balance of the pads gives the residual
   ``g_i = l_i + c_i (x0.f_i + mu_i N0)`` (``c_i = 1/k_ipi``).
5. Dynamics.  Euler's law about the fixed point O,
   ``d/dt|_N H_O = M_supports + M_A z0 + p_1 x f_1 + p_2 x f_2`` with
   ``H_O = I_O . w`` (``I_O = diag(Theta, Theta, Phi)`` in B) and
   ``M_supports = -(k_t q1 + d_t dq1) x0 - (k_t q2 + d_t dq2) y1``.  Only the
   x0 and y0 components are kept (M_A drops out) and ``dq3``, ``ddq3`` are
   eliminated with the non-holonomic constraint ``z0 . w = Omega``.

The result ``psi`` (2x1) and ``g`` (2x1) are sympy expressions in the plain
symbols of :data:`STATE` and :data:`PARAMS` (q3 set to 0; ``psi_q3``/``g_q3``
keep q3 as a symbol for the independence check).  Numerics are done with mpmath at
``DPS`` decimal digits and returned as float arrays.

API: :func:`reference_model`, :func:`residuals`, :func:`jacobians` (exact
symbolic derivatives, keys :data:`JACOBIAN_KEYS`), :func:`linearize`
(quasi-static pads: dl := 0, l eliminated from g = 0 by the implicit function
theorem), :func:`silent_motion`, and :func:`trivial_linearization_symbolic`
(closed-form M, D, K at the zero state).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import mpmath
import numpy as np
import sympy as sp
import sympy.physics.mechanics as me

STATE = ("q1", "q2", "dq1", "dq2", "ddq1", "ddq2", "l1", "l2", "dl1", "dl2")
PARAMS = (
    "Theta", "Phi", "k_t", "d_t", "k1", "k2", "d1", "d2", "c_ip1", "c_ip2",
    "mu1", "mu2", "h10", "h20", "r", "N0", "Omega",
)
GROUPS = {
    "q": ("q1", "q2"),
    "dq": ("dq1", "dq2"),
    "ddq": ("ddq1", "ddq2"),
    "l": ("l1", "l2"),
    "dl": ("dl1", "dl2"),
}
JACOBIAN_KEYS = ("psi_q", "psi_dq", "psi_ddq", "psi_l", "psi_dl",
                 "g_q", "g_dq", "g_l", "g_dl")
DPS = 30  # working precision of the numeric evaluation (decimal digits)


@dataclass
class ReferenceModel:
    """Symbolic reference model (all expressions in plain sympy symbols)."""

    psi: sp.Matrix                      # 2x1, q3 = 0
    g: sp.Matrix                        # 2x1
    psi_q3: sp.Matrix                   # 2x1, q3 kept as symbol ``q3``
    g_q3: sp.Matrix                     # 2x1, q3 kept as symbol ``q3``
    state: dict[str, sp.Symbol]
    params: dict[str, sp.Symbol]
    q3: sp.Symbol
    extras: dict[str, Any] = field(default_factory=dict)  # h_i, Fn_i, v_ri, ...
    jac: dict[str, sp.Matrix] = field(default_factory=dict)

    def __getitem__(self, key: str) -> Any:  # dict-like access
        return getattr(self, key)


def _rot(axis: str, a: sp.Expr) -> sp.Matrix:
    c, s = sp.cos(a), sp.sin(a)
    if axis == "x":
        return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])
    if axis == "y":
        return sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


@functools.lru_cache(maxsize=None)
def reference_model() -> ReferenceModel:
    """Derive psi and g (cached)."""
    t = me.dynamicsymbols._t
    q1, q2, q3, l1, l2 = me.dynamicsymbols("q1 q2 q3 l1 l2")
    P = {name: sp.Symbol(name, real=True) for name in PARAMS}
    (Theta, Phi, k_t, d_t, k1, k2, d1, d2, c1, c2, mu1, mu2, h10, h20, r, N0,
     Omega) = (P[n] for n in PARAMS)

    # --- frames -----------------------------------------------------------
    N = me.ReferenceFrame("N")
    A1 = N.orientnew("A1", "Axis", (q1, N.x))          # intermediate frame 1
    B = N.orientnew("B", "Body", (q1, q2, q3), "XYZ")  # disk
    dcm = N.dcm(B)  # N-components = dcm * B-components
    assert sp.simplify(dcm - _rot("x", q1) * _rot("y", q2) * _rot("z", q3)) == sp.zeros(3, 3)
    w = B.ang_vel_in(N)

    # --- contact geometry ---------------------------------------------------
    O = me.Point("O")
    O.set_vel(N, 0)
    zB = B.z
    cosz = sp.trigsimp(N.z.dot(zB))  # z0 . z_B = cos q1 cos q2
    pl1 = l1 * N.x - r * N.y - h10 * N.z
    pl2 = l2 * N.x - r * N.y + h20 * N.z
    h1 = -(pl1.dot(zB) + h10) / cosz
    h2 = -(pl2.dot(zB) - h20) / cosz
    h1, h2 = sp.trigsimp(h1), sp.trigsimp(h2)
    p1 = pl1 + h1 * N.z
    p2 = pl2 + h2 * N.z

    P1 = O.locatenew("P1", p1)  # contact point (moves along the pad line)
    P2 = O.locatenew("P2", p2)
    D1 = O.locatenew("D1", p1)  # disk material point coincident with P1
    D2 = O.locatenew("D2", p2)
    D1.v2pt_theory(O, N, B)
    D2.v2pt_theory(O, N, B)
    vr1 = P1.pos_from(O).dt(N) - D1.vel(N)
    vr2 = P2.pos_from(O).dt(N) - D2.vel(N)

    def unit(v: me.Vector) -> me.Vector:
        m = v.to_matrix(N)
        return v / sp.sqrt(m.dot(m))

    t1, t2 = unit(vr1), unit(vr2)
    dh1, dh2 = h1.diff(t), h2.diff(t)

    # --- pad equilibrium ------------------------------------------------------
    Fn1 = (N0 - k1 * h1 - d1 * dh1) / (cosz + mu1 * N.z.dot(t1))
    Fn2 = (N0 + k2 * h2 + d2 * dh2) / (cosz - mu2 * N.z.dot(t2))
    f1 = Fn1 * zB + mu1 * Fn1 * t1
    f2 = -Fn2 * zB + mu2 * Fn2 * t2
    g_dyn = [l1 + c1 * (N.x.dot(f1) + mu1 * N0),
             l2 + c2 * (N.x.dot(f2) + mu2 * N0)]

    # --- Euler's law about O ----------------------------------------------------
    disk = me.RigidBody("disk", O, B, sp.Symbol("m"), (me.inertia(B, Theta, Theta, Phi), O))
    H = disk.angular_momentum(O, N)
    Hdot = H.dt(N)
    M_sup = -(k_t * q1 + d_t * q1.diff(t)) * N.x - (k_t * q2 + d_t * q2.diff(t)) * A1.y
    res = Hdot - M_sup - p1.cross(f1) - p2.cross(f2)
    psi_dyn = [res.dot(N.x), res.dot(N.y)]

    # --- non-holonomic constraint, then plain symbols -----------------------------
    dq3_expr = (Omega - q2.diff(t) * sp.sin(q1)) / (sp.cos(q1) * sp.cos(q2))
    assert sp.simplify(w.dot(N.z).subs(q3.diff(t), dq3_expr) - Omega) == 0
    ddq3_expr = dq3_expr.diff(t)
    stage1 = {q3.diff(t, 2): ddq3_expr, q3.diff(t): dq3_expr}
    S = {name: sp.Symbol(name, real=True) for name in STATE}
    q3s = sp.Symbol("q3", real=True)
    stage2 = {
        q1.diff(t, 2): S["ddq1"], q2.diff(t, 2): S["ddq2"],
        q1.diff(t): S["dq1"], q2.diff(t): S["dq2"],
        l1.diff(t): S["dl1"], l2.diff(t): S["dl2"],
        q1: S["q1"], q2: S["q2"], q3: q3s, l1: S["l1"], l2: S["l2"],
    }

    def plain(e: sp.Expr) -> sp.Expr:
        e = e.xreplace(stage1)
        e = e.xreplace(stage2)
        assert not e.atoms(sp.Derivative), e.atoms(sp.Derivative)
        return e

    psi_q3 = sp.Matrix([plain(e) for e in psi_dyn])
    g_q3 = sp.Matrix([plain(e) for e in g_dyn])
    psi = psi_q3.xreplace({q3s: 0})
    g = g_q3.xreplace({q3s: 0})
    extras = {
        "h1": plain(h1), "h2": plain(h2), "dh1": plain(dh1), "dh2": plain(dh2),
        "Fn1": plain(Fn1).xreplace({q3s: 0}), "Fn2": plain(Fn2).xreplace({q3s: 0}),
        "vr1": sp.Matrix([plain(c) for c in vr1.to_matrix(N)]).xreplace({q3s: 0}),
        "vr2": sp.Matrix([plain(c) for c in vr2.to_matrix(N)]).xreplace({q3s: 0}),
        "frames": (N, A1, B),
    }
    model = ReferenceModel(psi=psi, g=g, psi_q3=psi_q3, g_q3=g_q3, state=S, params=P, q3=q3s,
                           extras=extras)
    for lhs, expr in (("psi", psi), ("g", g)):
        for grp, names in GROUPS.items():
            key = f"{lhs}_{grp}"
            if key in JACOBIAN_KEYS:
                model.jac[key] = expr.jacobian([S[n] for n in names])
    return model


# ----------------------------------------------------------------------------
# numerics (mpmath at DPS digits)
# ----------------------------------------------------------------------------

def _args(model: ReferenceModel, with_q3: bool = False) -> list[sp.Symbol]:
    a = [model.state[n] for n in STATE] + [model.params[n] for n in PARAMS]
    return a + [model.q3] if with_q3 else a


@functools.lru_cache(maxsize=None)
def _function(kind: str) -> Callable:
    """Lambdified (mpmath, cse) evaluators, built on first use and cached."""
    m = reference_model()
    # flat output lists: lambdify's cse is much slower on nested lists
    if kind == "residual":
        return sp.lambdify(_args(m), list(m.psi) + list(m.g), modules="mpmath", cse=True)
    if kind == "residual_q3":
        return sp.lambdify(_args(m, True), list(m.psi_q3) + list(m.g_q3),
                           modules="mpmath", cse=True)
    if kind == "jac":
        return sp.lambdify(_args(m), [e for k in JACOBIAN_KEYS for e in m.jac[k]],
                           modules="mpmath", cse=True)
    raise ValueError(kind)


def _values(state: Mapping[str, float], params: Mapping[str, float]) -> list:
    """mpf argument list; missing state entries are 0, unknown keys are errors."""
    missing = [p for p in PARAMS if p not in params]
    unknown = [k for k in state if k not in STATE and k != "q3"]
    unknown += [k for k in params if k not in PARAMS]
    if missing or unknown:
        raise KeyError(f"missing parameters {missing}, unknown keys {unknown}")
    vals = [mpmath.mpf(state.get(n, 0.0)) for n in STATE]
    return vals + [mpmath.mpf(params[n]) for n in PARAMS]


def _to_np(x) -> np.ndarray:
    return np.array(x, dtype=object).astype(float)


def residuals(state: Mapping[str, float], params: Mapping[str, float]
              ) -> tuple[np.ndarray, np.ndarray]:
    """Numeric (psi, g), each of shape (2,). Missing state entries default to 0.

    If ``state`` contains ``"q3"`` the q3-dependent expressions are used (they
    must give the same values; see the tests).
    """
    with mpmath.workdps(DPS):
        vals = _values(state, params)
        if "q3" in state:
            out = _function("residual_q3")(*vals, mpmath.mpf(state["q3"]))
        else:
            out = _function("residual")(*vals)
        return _to_np(out[:2]), _to_np(out[2:])


def jacobians(state: Mapping[str, float], params: Mapping[str, float]
              ) -> dict[str, np.ndarray]:
    """Exact (symbolic) 2x2 derivative blocks of psi and g, see JACOBIAN_KEYS."""
    with mpmath.workdps(DPS):
        out = _to_np(_function("jac")(*_values(state, params))).reshape(-1, 2, 2)
        return dict(zip(JACOBIAN_KEYS, out))


def linearize(state0: Mapping[str, float], params: Mapping[str, float]
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(M, D, K) about an equilibrium, pads quasi-static: dl := 0 and
    l eliminated from g = 0 by the implicit function theorem."""
    J = jacobians(state0, params)
    E = J["psi_l"] @ np.linalg.inv(J["g_l"])
    M = J["psi_ddq"]
    D = J["psi_dq"] - E @ J["g_dq"]
    K = J["psi_q"] - E @ J["g_q"]
    return M, D, K


def silent_motion(params: Mapping[str, float], tol: float = 1e-13) -> dict[str, float]:
    """Solve psi = 0, g = 0 with dq = ddq = dl = 0 for (q1, q2, l1, l2)."""
    from scipy.optimize import root

    names = ("q1", "q2", "l1", "l2")

    def state_of(x):
        s = dict.fromkeys(STATE, 0.0)
        s.update(zip(names, map(float, x)))
        return s

    # scale rows so both residual types are O(1) near the solution
    J0 = jacobians(state_of(np.zeros(4)), params)
    row_scale = np.concatenate([np.abs(np.hstack([J0["psi_q"], J0["psi_l"]])).max(axis=1),
                                np.abs(np.hstack([J0["g_q"], J0["g_l"]])).max(axis=1)])
    row_scale[row_scale == 0] = 1.0

    def fun(x):
        psi, g = residuals(state_of(x), params)
        return np.concatenate([psi, g]) / row_scale

    def jac(x):
        J = jacobians(state_of(x), params)
        return np.block([[J["psi_q"], J["psi_l"]], [J["g_q"], J["g_l"]]]) / row_scale[:, None]

    sol = root(fun, np.zeros(4), jac=jac, method="hybr", options={"xtol": 1e-15})
    x = sol.x
    step = np.inf
    for _ in range(4):  # Newton polish with the exact Jacobian
        dx = np.linalg.solve(jac(x), fun(x))
        x = x - dx
        step = np.max(np.abs(dx))
        if step <= tol * np.max(np.abs(x)) or step == 0.0:
            break
    else:
        raise RuntimeError(f"silent motion not converged ({sol.message}); last step {step:g}")
    return state_of(x)


@functools.lru_cache(maxsize=None)
def trivial_linearization_symbolic() -> tuple[sp.Matrix, sp.Matrix, sp.Matrix]:
    """Closed-form (M, D, K) at q = dq = ddq = l = dl = 0 with quasi-static pads.

    The zero state is an equilibrium iff mu1*h10 == mu2*h20.  The expressions
    use the parameter symbols of :func:`reference_model` (simplified under the
    physical sign assumptions r, h_i0, N0, Omega, ... > 0).
    """
    m = reference_model()
    zero = {m.state[n]: 0 for n in STATE}
    nonneg = ("d_t", "d1", "d2", "c_ip1", "c_ip2", "mu1", "mu2")
    phys = {m.params[n]: sp.Symbol(n, nonnegative=True) if n in nonneg
            else sp.Symbol(n, positive=True) for n in PARAMS}
    back = {v: k for k, v in phys.items()}
    J = {k: v.xreplace(zero).xreplace(phys).applyfunc(sp.simplify) for k, v in m.jac.items()}
    E = J["psi_l"] * J["g_l"].inv()
    M = J["psi_ddq"]
    D = J["psi_dq"] - E * J["g_dq"]
    K = J["psi_q"] - E * J["g_q"]
    return tuple(X.applyfunc(lambda e: sp.expand(sp.simplify(e)).xreplace(back)) for X in (M, D, K))
