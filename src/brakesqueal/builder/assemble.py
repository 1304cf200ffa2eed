r"""Generic assembly of the equations of a :class:`~.components.ModelSpec`.

The disk's tilting DOFs follow the paper's procedure unchanged (matrix Euler
equations with Kronecker products, eqs. 35-38; constraint elimination,
eqs. 40-45), with the contact moments summed over the pads.  Each pad
contributes its contact kinematics (eqs. 12-28, generalized to an angular
position), and, depending on its DOFs, either the massless relations of the
paper (normal force from eqs. 29-30, quasi-static tangential equilibrium
eqs. 33-34) or Newton's law for its mass.  Calipers add Newton's law for their
translations.

The result is the residual ``R(Q, Qdot, Qddot, L) = 0`` (one row per
coordinate of ``Q``) and the algebraic residual ``G(Q, Qdot, L) = 0`` of the
massless pads' tangential deformations ``L``; linearization follows
:mod:`brakesqueal.symbolic.linearize`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

from ..symbolic.backend import Backend, get_backend
from ..symbolic.constraint import reduce_equations, spin_constraint
from ..symbolic.euler import euler_matrices
from ..symbolic.kinematics import CardanKinematics, cardan_kinematics, tilde
from .components import FrictionLaw, ModelSpec, Pad

__all__ = ["BuiltEquations", "build_equations", "compliance_name"]


def compliance_name(name: str) -> str:
    """Internal name of the compliance ``1/k_ip`` for a stiffness parameter ``name``."""
    return f"c__{name}"


@dataclass(frozen=True)
class BuiltEquations:
    """Symbolic equations of a built model.

    Attributes
    ----------
    spec : ModelSpec
        The model the equations were assembled from.
    coords : tuple of str
        Names of the coordinates ``Q`` (``q1, q2`` of the disk, ``w_<pad>``,
        ``u_<pad>`` of pad DOFs, ``wc_<caliper>``, ``uc_<caliper>``).
    algebraic : tuple of str
        Names of the quasi-static tangential deformations ``L`` (``l_<pad>``).
    R, G : Matrix
        Residuals (``len(coords)`` and ``len(algebraic)`` rows; ``G`` is
        ``None`` when there are no quasi-static pads).
    x : list
        Symbols in the order ``Q, Qdot, Qddot, L``.
    params : list
        Parameter symbols in :meth:`ModelSpec.parameter_names` order, with
        tangential stiffnesses replaced by their compliances.
    normal_forces, sliding_speeds : list
        Per pad, in ``spec.pads`` order.
    """

    spec: ModelSpec
    coords: tuple[str, ...]
    algebraic: tuple[str, ...]
    R: Any
    G: Any
    x: list[Any]
    params: list[Any]
    normal_forces: list[Any]
    sliding_speeds: list[Any]


class _Ctx:
    def __init__(self, sm: Any, spec: ModelSpec) -> None:
        self.sm = sm
        self.spec = spec
        self.kip = spec.stiffness_names()
        self.sym = {n: sm.Symbol(compliance_name(n) if n in self.kip else n) for n in spec.parameter_names()}

    def val(self, v: Any) -> Any:
        if v is None:
            return self.sm.Integer(0)
        if isinstance(v, str):
            return self.sym[v]
        return self.sm.Integer(int(v)) if float(v).is_integer() else self.sm.sympify(float(v))

    def compliance(self, v: Any) -> Any:
        """``1/k_ip`` (0 for a rigid support)."""
        if isinstance(v, str):
            return self.sym[v]
        return self.sm.Integer(0) if math.isinf(v) else 1 / self.val(v)

    def stiffness(self, v: Any) -> Any:
        return 1 / self.sym[v] if isinstance(v, str) else self.val(v)


def _friction(ctx: _Ctx, law: FrictionLaw, v: Any) -> Any:
    sm = ctx.sm
    mu = ctx.val(law.mu)
    if law.law == "coulomb":
        return mu
    if law.law == "linear":
        return mu - ctx.val(law.slope) * v
    return mu + (ctx.val(law.mu_s) - mu) * sm.exp(-v / ctx.val(law.v_s))


def _angle(sm: Any, deg: float) -> tuple[Any, Any]:
    fr = Fraction(deg).limit_denominator(10**6)
    a = sm.pi * sm.Integer(fr.numerator) / sm.Integer(fr.denominator * 180)
    return sm.cos(a), sm.sin(a)


def build_equations(spec: ModelSpec, backend: Backend = "symengine") -> BuiltEquations:
    """Assemble the nonlinear equations of a model described by components.

    Parameters
    ----------
    spec : ModelSpec
        The model.
    backend : {"symengine", "sympy"}
        Computer-algebra backend.

    Returns
    -------
    BuiltEquations
    """
    sm = get_backend(backend)
    ctx = _Ctx(sm, spec)
    disk = spec.disk
    Omega = ctx.val(disk.Omega)
    coords: list[str] = []
    q_m: tuple[Any, ...] = ()
    if disk.tilting:
        coords += ["q1", "q2"]
    for p in spec.pads:
        coords += [f"{'w' if d == 'normal' else 'u'}_{p.name}" for d in ("normal", "tangential") if d in p.dofs]
    for c in spec.calipers:
        coords += [f"{'wc' if d == 'normal' else 'uc'}_{c.name}" for d in ("normal", "tangential") if d in c.dofs]
    algebraic = [f"l_{p.name}" for p in spec.pads if "tangential" not in p.dofs and not _rigid(p)]
    Q = {n: sm.Symbol(n) for n in coords}
    dQ = {n: sm.Symbol(f"d{n}") for n in coords}
    ddQ = {n: sm.Symbol(f"dd{n}") for n in coords}
    L = {n: sm.Symbol(n) for n in algebraic}

    def rate(e: Any) -> Any:  # time derivative along the motion, quasi-static L (Ldot := 0)
        return sum((e.diff(Q[n]) * dQ[n] for n in coords), sm.Integer(0))

    z0 = sm.Matrix([0, 0, 1])
    if disk.tilting:
        q_m = (Q["q1"], Q["q2"])
        q3 = sm.Symbol("q3")
        kin = cardan_kinematics(sm, (q_m[0], q_m[1], q3))
        sub = {q3: sm.Integer(0)}
        kin = CardanKinematics(A=kin.A.subs(sub), A1=kin.A1, A2=kin.A2, J_R0=kin.J_R0, J_R3=kin.J_R3.subs(sub),
                               H_R0=kin.H_R0, H_R3=kin.H_R3.subs(sub), q=kin.q)  # fmt: skip
        con = spin_constraint(sm, q_m, Omega)
        omega0 = kin.J_R0 * (con.s + con.S * sm.Matrix([dQ["q1"], dQ["q2"]]))
        z3 = kin.A[:, 2]
    else:
        omega0 = z0 * Omega
        z3 = z0
    cal = {c.name: c for c in spec.calipers}
    rows: dict[str, Any] = {}
    G_rows: list[Any] = []
    moment = sm.zeros(3, 1)
    cal_normal: dict[str, Any] = {c.name: sm.Integer(0) for c in spec.calipers}
    cal_tang: dict[str, Any] = {c.name: sm.Integer(0) for c in spec.calipers}
    fns, speeds = [], []
    for pad in spec.pads:
        s = 1 if pad.face == "upper" else -1
        h0 = ctx.val(disk.h_upper if s == 1 else disk.h_lower)
        r, N0, k, d = ctx.val(pad.radius), ctx.val(pad.preload), ctx.val(pad.k), ctx.val(pad.d)
        ca, sa = _angle(sm, pad.angle_deg)
        e_t = sm.Matrix([ca, sa, 0])
        base = sm.Matrix([r * sa, -r * ca, 0])
        mount = cal.get(pad.mount) if pad.mount else None
        w_m = Q[f"wc_{mount.name}"] if mount and "normal" in mount.dofs else sm.Integer(0)
        u_m = Q[f"uc_{mount.name}"] * ca if mount and "tangential" in mount.dofs else sm.Integer(0)
        if "tangential" in pad.dofs:
            l = Q[f"u_{pad.name}"]
        elif _rigid(pad):
            l = u_m
        else:
            l = L[f"l_{pad.name}"]
        p_l = base + e_t * l + z0 * (-s * h0)
        z3_pl = z3[0] * p_l[0] + z3[1] * p_l[1] + z3[2] * p_l[2]
        h = (-s * h0 - z3_pl) / z3[2]  # eq. (16), third row
        p = p_l + z0 * h
        pdot = sm.Matrix([rate(p[i]) for i in range(3)])
        v_r = pdot - tilde(sm, omega0) * p
        speed = sm.sqrt(v_r[0] ** 2 + v_r[1] ** 2 + v_r[2] ** 2)
        t_p = v_r / speed
        mu = _friction(ctx, pad.friction, speed)
        mu_star = _friction(ctx, pad.friction, Omega * r)  # at the nominal sliding speed
        hdot, wdot_m = rate(h), rate(w_m)
        if "normal" in pad.dofs:
            w = Q[f"w_{pad.name}"]
            delta = s * (w - h)
            Fn = N0 + ctx.val(pad.k_c) * delta + ctx.val(pad.d_c) * rate(delta)
            F_s = s * N0 - k * (w - w_m) - d * (dQ[f"w_{pad.name}"] - wdot_m)
        else:
            F_s = s * N0 - k * (h - w_m) - d * (hdot - wdot_m)
            Fn = F_s / (s * z3[2] + mu * t_p[2])  # eqs. (29)-(30)
        f_p = z3 * (s * Fn) + t_p * (mu * Fn)  # eqs. (27)-(28)
        ft = e_t[0] * f_p[0] + e_t[1] * f_p[1]
        if "normal" in pad.dofs:
            n = f"w_{pad.name}"
            rows[n] = ctx.val(pad.mass) * ddQ[n] - F_s + f_p[2]
        else:
            F_s = f_p[2]  # massless: the support carries the contact force
        if "tangential" in pad.dofs:
            n = f"u_{pad.name}"
            u_m_dot = rate(u_m)
            F_t = -(ctx.stiffness(pad.k_ip) * (l - u_m) + ctx.val(pad.d_ip) * (dQ[n] - u_m_dot) + mu_star * N0)
            rows[n] = ctx.val(pad.mass) * ddQ[n] - F_t + ft
        else:
            F_t = ft
            if not _rigid(pad):
                G_rows.append((l - u_m) + ctx.compliance(pad.k_ip) * (ft + mu_star * N0))  # eqs. (33)-(34)
        if mount:
            cal_normal[mount.name] += F_s - s * N0
            cal_tang[mount.name] += (F_t + mu_star * N0) * ca
        moment = moment + tilde(sm, p) * f_p
        fns.append(Fn)
        speeds.append(speed)
    for c in spec.calipers:
        if "normal" in c.dofs:
            n = f"wc_{c.name}"
            rows[n] = ctx.val(c.mass) * ddQ[n] + ctx.val(c.k_n) * Q[n] + ctx.val(c.d_n) * dQ[n] + cal_normal[c.name]
        if "tangential" in c.dofs:
            n = f"uc_{c.name}"
            rows[n] = ctx.val(c.mass) * ddQ[n] + ctx.val(c.k_t) * Q[n] + ctx.val(c.d_t) * dQ[n] + cal_tang[c.name]
    if disk.tilting:
        I3 = sm.diag(ctx.val(disk.Theta), ctx.val(disk.Theta), ctx.val(disk.Phi))
        M0, Cstar0 = euler_matrices(sm, kin, I3)
        red = reduce_equations(
            sm, M0, Cstar0, con, q_m, (dQ["q1"], dQ["q2"]), (ddQ["q1"], ddQ["q2"]),
            ctx.val(disk.k_t), ctx.val(disk.d_t), moment,
        )  # fmt: skip
        rows["q1"], rows["q2"] = red.psi[0], red.psi[1]
    R = sm.Matrix([rows[n] for n in coords])
    G = sm.Matrix(G_rows) if G_rows else None
    x = [Q[n] for n in coords] + [dQ[n] for n in coords] + [ddQ[n] for n in coords] + [L[n] for n in algebraic]
    params = [ctx.sym[n] for n in spec.parameter_names()]
    return BuiltEquations(spec, tuple(coords), tuple(algebraic), R, G, x, params, fns, speeds)


def _rigid(pad: Pad) -> bool:
    return not isinstance(pad.k_ip, str) and math.isinf(pad.k_ip)
