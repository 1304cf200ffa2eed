r"""Assembly of the nonlinear equations of any model (the paper's procedure, eqs. 2-45).

The disk's tilting DOFs follow the paper unchanged: Cardan kinematics (eqs.
2-11), matrix Euler equations with Kronecker products (eqs. 35-38) and the
elimination of the spin constraint (eqs. 40-45), with the contact moments
summed over the pads.  Each pad contributes its contact (:mod:`.contact`,
eqs. 12-34) and, depending on its DOFs, either the massless relations of the
paper or Newton's law for its mass; calipers add Newton's law for their
translations.

Result: residuals ``R(Q, Qdot, Qddot, L, Ldot) = 0`` (one row per coordinate
of ``Q``) and ``G(Q, Qdot, L, Ldot) = 0`` (tangential balance of every massless
pad with a finite tangential stiffness, unknown ``L``), with the state
``x = (Q, Qdot, Qddot, L, Ldot)`` and parameters in the model's canonical
order, tangential stiffnesses replaced by compliances ``c = 1/k_ip`` so that a
rigid support (``k_ip = inf``) is the regular value ``c = 0``.  The pads'
tangential rates ``Ldot`` are kept: how they enter the linearization and the
simulation is decided there (:mod:`brakesqueal.analysis.linear`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from .backend import Backend, get_backend
from .constraint import ReducedEquations, reduce_equations, spin_constraint
from .contact import PadContact, angle_cos_sin, friction_coefficient, pad_contact
from .euler import angular_momentum_rate, euler_matrices, support_moment
from .kinematics import CardanKinematics, cardan_kinematics

__all__ = ["Equations", "build_equations", "compliance_name"]


def compliance_name(name: str, taken: Any = ()) -> str:
    """Name of the compliance ``1/k`` of a stiffness parameter: ``k_ip1 -> c_ip1``, else ``c__<name>``."""
    cand = "c" + name[1:] if name.startswith("k_") else f"c__{name}"
    return cand if cand not in taken else f"c__{name}"


@dataclass(frozen=True)
class Equations:
    """Symbolic equations of a model.

    Attributes
    ----------
    spec : ModelSpec
        The model.
    coords : tuple of str
        Generalized coordinates ``Q``: ``q1, q2`` (disk tilt), ``w_<pad>``,
        ``u_<pad>`` (pad DOFs), ``wc_<caliper>``, ``uc_<caliper>`` (without
        the underscore for components named by digits: ``w1``).
    algebraic : tuple of str
        Tangential deformations ``L`` of the massless pads with a finite
        tangential stiffness: ``l_<pad>`` (``l1``, ``l2`` for the paper's pads).
    R, G : Matrix
        Residuals (``G`` is ``None`` when ``L`` is empty).
    Q, dQ, ddQ, L, dL : list
        Symbols of the state parts, in coordinate order.
    params : list
        Parameter symbols in the model's canonical order (``spec.parameters``),
        tangential stiffnesses replaced by their compliances.
    param_names : tuple of str
        Names of ``params`` (compliance names for the tangential stiffnesses).
    pads : tuple of PadContact
        Contact quantities per pad (in ``spec.pads`` order).
    tangential : tuple
        Per pad, its tangential position expression ``l`` (coordinate, ``L``
        symbol, mount displacement or 0).
    reduced : ReducedEquations or None
        The disk's matrices of eq. (45) (``None`` for a non-tilting disk or
        the chain-rule route).
    kinematics : CardanKinematics or None
        Disk kinematics (eqs. 2-11).
    constraint_qdot : Matrix or None
        ``qdot = s + S q_mdot`` (eq. 41) of the disk.
    backend : str
        ``"symengine"`` or ``"sympy"``.
    """

    spec: Any
    coords: tuple[str, ...]
    algebraic: tuple[str, ...]
    R: Any
    G: Any
    Q: list[Any]
    dQ: list[Any]
    ddQ: list[Any]
    L: list[Any]
    dL: list[Any]
    params: list[Any]
    param_names: tuple[str, ...]
    pads: tuple[PadContact, ...]
    tangential: tuple[Any, ...]
    reduced: ReducedEquations | None
    kinematics: CardanKinematics | None
    constraint_qdot: Any
    backend: str

    @property
    def x(self) -> list[Any]:
        """State symbols ``(Q, Qdot, Qddot, L, Ldot)``."""
        return [*self.Q, *self.dQ, *self.ddQ, *self.L, *self.dL]

    @property
    def n(self) -> int:
        """Number of coordinates."""
        return len(self.coords)

    @property
    def m(self) -> int:
        """Number of pad deformations ``L``."""
        return len(self.algebraic)

    def symbol(self, name: str) -> Any:
        """The symbol of a coordinate, rate, deformation or parameter by name."""
        for s in (*self.x, *self.params):
            if str(s) == name:
                return s
        raise KeyError(name)


def _name(prefix: str, component: str) -> str:
    """State name of a component: ``l1`` for pad ``"1"`` (the paper's names), ``l_upper`` otherwise."""
    return f"{prefix}{component}" if component.isdigit() else f"{prefix}_{component}"


def _rigid(pad: Any) -> bool:
    return not isinstance(pad.k_ip, str) and math.isinf(pad.k_ip)


class _Values:
    """Component field → symbolic value (names → symbols, stiffness names → 1/compliance)."""

    def __init__(self, sm: Any, spec: Any) -> None:
        self.sm = sm
        self.kip = spec.stiffness_names()
        names = list(spec.parameters)
        taken = set(names)
        self.pname = {n: (compliance_name(n, taken) if n in self.kip else n) for n in names}
        self.sym = {n: sm.Symbol(self.pname[n]) for n in names}

    def __call__(self, v: Any) -> Any:
        if v is None:
            return self.sm.Integer(0)
        if isinstance(v, str):
            return 1 / self.sym[v] if v in self.kip else self.sym[v]
        return self.sm.Integer(int(v)) if float(v).is_integer() else self.sm.sympify(float(v))

    def compliance(self, v: Any) -> Any:
        if isinstance(v, str):
            return self.sym[v]
        return self.sm.Integer(0) if math.isinf(v) else 1 / self.__call__(v)


def build_equations(spec: Any, backend: Backend = "symengine", *, kronecker: bool = True,
                    keep_q3: bool = False, engagement: Any = None) -> Equations:
    """Assemble the nonlinear equations of a model.

    Parameters
    ----------
    spec : ModelSpec
        The model (:mod:`brakesqueal.model`).
    backend : {"symengine", "sympy"}
        Computer-algebra backend.
    kronecker : bool
        ``True`` (default): the disk's equations from the matrix Euler
        equations with Kronecker products (eqs. 35-37, 44-45).  ``False``:
        the chain-rule derivative of the angular momentum with the constraint
        substituted directly (the comparison route of the paper's 5 % claim).
    keep_q3 : bool
        Keep the spin angle ``q3`` as a symbol (it drops out for an
        axisymmetric disk; tests check that).  Default: ``q3 = 0``.
    engagement : mapping, optional
        Pad name -> factor of that pad's contact force (unilateral contact in
        the simulation kernels); default: every pad pressed.

    Returns
    -------
    Equations
    """
    sm = get_backend(backend)
    val = _Values(sm, spec)
    disk = spec.disk
    Omega = val(disk.Omega)
    coords: list[str] = ["q1", "q2"] if disk.tilting else []
    for p in spec.pads:
        coords += [_name("w" if d == "normal" else "u", p.name) for d in ("normal", "tangential") if d in p.dofs]
    for c in spec.calipers:
        coords += [_name("wc" if d == "normal" else "uc", c.name) for d in ("normal", "tangential") if d in c.dofs]
    algebraic = [_name("l", p.name) for p in spec.pads if "tangential" not in p.dofs and not _rigid(p)]
    Q = {n: sm.Symbol(n) for n in coords}
    dQ = {n: sm.Symbol(f"d{n}") for n in coords}
    ddQ = {n: sm.Symbol(f"dd{n}") for n in coords}
    L = {n: sm.Symbol(n) for n in algebraic}
    dL = {n: sm.Symbol(f"d{n}") for n in algebraic}

    def rate(e: Any) -> Any:
        """Time derivative of an expression of ``Q`` and ``L`` along the motion."""
        out = sm.Integer(0)
        for n in coords:
            out += e.diff(Q[n]) * dQ[n]
        for n in algebraic:
            out += e.diff(L[n]) * dL[n]
        return out

    z0 = sm.Matrix([0, 0, 1])
    kin = con = qdot = None
    if disk.tilting:
        q_m = (Q["q1"], Q["q2"])
        q3 = sm.Symbol("q3")
        kin = cardan_kinematics(sm, (q_m[0], q_m[1], q3))
        if not keep_q3:
            sub = {q3: sm.Integer(0)}
            kin = CardanKinematics(A=kin.A.subs(sub), A1=kin.A1, A2=kin.A2, J_R0=kin.J_R0,
                                   J_R3=kin.J_R3.subs(sub), H_R0=kin.H_R0, H_R3=kin.H_R3.subs(sub), q=kin.q)
        con = spin_constraint(sm, q_m, Omega)
        qdot = con.s + con.S * sm.Matrix([dQ["q1"], dQ["q2"]])  # eq. (41)
        omega0 = kin.J_R0 * qdot  # eq. (6) with the constraint
        z3 = kin.A[:, 2]
    else:
        omega0 = z0 * Omega
        z3 = z0
    cal = {c.name: c for c in spec.calipers}
    rows: dict[str, Any] = {}
    G_rows: list[Any] = []
    moment = sm.zeros(3, 1)
    cal_normal = {c.name: sm.Integer(0) for c in spec.calipers}
    cal_tang = {c.name: sm.Integer(0) for c in spec.calipers}
    contacts: list[PadContact] = []
    tangential: list[Any] = []
    for pad in spec.pads:
        s = 1 if pad.face == "upper" else -1
        r, N0 = val(pad.radius), val(pad.preload)
        ca, sa = angle_cos_sin(sm, pad.angle_deg)
        e_t = sm.Matrix([ca, sa, 0])
        base = sm.Matrix([r * sa, -r * ca, 0])
        mount = cal.get(pad.mount) if pad.mount else None
        w_m = Q[_name("wc", mount.name)] if mount and "normal" in mount.dofs else sm.Integer(0)
        u_m = Q[_name("uc", mount.name)] * ca if mount and "tangential" in mount.dofs else sm.Integer(0)
        if "tangential" in pad.dofs:
            l = Q[_name("u", pad.name)]
        elif _rigid(pad):
            l = u_m
        else:
            l = L[_name("l", pad.name)]
        normal = "normal" in pad.dofs
        quasi = "tangential" not in pad.dofs and not _rigid(pad)
        law = pad.friction

        def mu_of(v: Any, law: Any = law) -> Any:
            return friction_coefficient(sm, law, v, val)

        c = pad_contact(
            sm, side=s, h0=val(disk.h_upper if s == 1 else disk.h_lower), base=base, e_t=e_t, l=l, z3=z3,
            omega0=omega0, rate=rate, friction=mu_of,
            N0=N0, nominal_speed=Omega * r, k=val(pad.k), d=val(pad.d), w_m=w_m,
            normal_dof=Q[_name("w", pad.name)] if normal else None, k_c=val(pad.k_c) if normal else None,
            d_c=val(pad.d_c) if normal else None, u_m=u_m, compliance=val.compliance(pad.k_ip) if quasi else None,
            engaged=engagement.get(pad.name) if engagement else None,
            damping_t=val(pad.d_ip) if quasi else None,
        )  # fmt: skip
        if normal:
            n = _name("w", pad.name)
            rows[n] = val(pad.mass) * ddQ[n] - c.support_normal + c.f_p[2]
        if "tangential" in pad.dofs:
            n = _name("u", pad.name)
            F_t = -(val(pad.k_ip) * (l - u_m) + val(pad.d_ip) * (dQ[n] - rate(u_m)) + c.mu_star * N0)
            rows[n] = val(pad.mass) * ddQ[n] - F_t + c.f_t
        else:
            F_t = c.f_t
            if quasi:
                G_rows.append(c.g)
        if mount:
            cal_normal[mount.name] += c.support_normal - s * N0
            cal_tang[mount.name] += (F_t + c.mu_star * N0) * ca
        moment = moment + c.moment
        contacts.append(c)
        tangential.append(l)
    for cp in spec.calipers:
        if "normal" in cp.dofs:
            n = _name("wc", cp.name)
            rows[n] = val(cp.mass) * ddQ[n] + val(cp.k_n) * Q[n] + val(cp.d_n) * dQ[n] + cal_normal[cp.name]
        if "tangential" in cp.dofs:
            n = _name("uc", cp.name)
            rows[n] = val(cp.mass) * ddQ[n] + val(cp.k_t) * Q[n] + val(cp.d_t) * dQ[n] + cal_tang[cp.name]
    red = None
    if disk.tilting:
        I3 = sm.diag(val(disk.Theta), val(disk.Theta), val(disk.Phi))
        q_m, dq_m, ddq_m = (Q["q1"], Q["q2"]), (dQ["q1"], dQ["q2"]), (ddQ["q1"], ddQ["q2"])
        assert kin is not None and con is not None
        if kronecker:
            M0, Cstar0 = euler_matrices(sm, kin, I3)
            red = reduce_equations(sm, M0, Cstar0, con, q_m, dq_m, ddq_m, val(disk.k_t), val(disk.d_t), moment)
            rows["q1"], rows["q2"] = red.psi[0], red.psi[1]
        else:
            psi = _psi_without_kronecker(sm, kin, I3, con, dq_m, ddq_m, val(disk.k_t), val(disk.d_t), moment)
            rows["q1"], rows["q2"] = psi[0], psi[1]
    R = sm.Matrix([rows[n] for n in coords])
    G = sm.Matrix(G_rows) if G_rows else None
    return Equations(
        spec=spec, coords=tuple(coords), algebraic=tuple(algebraic), R=R, G=G, Q=[Q[n] for n in coords],
        dQ=[dQ[n] for n in coords], ddQ=[ddQ[n] for n in coords], L=[L[n] for n in algebraic],
        dL=[dL[n] for n in algebraic], params=[val.sym[n] for n in spec.parameters],
        param_names=tuple(val.pname[n] for n in spec.parameters), pads=tuple(contacts),
        tangential=tuple(tangential), reduced=red, kinematics=kin, constraint_qdot=qdot, backend=backend,
    )  # fmt: skip


def _psi_without_kronecker(sm: Any, kin: Any, I3: Any, con: Any, dq_m: Any, ddq_m: Any, k_t: Any, d_t: Any,
                           moment: Any) -> Any:
    """Chain-rule route: derivative of the angular momentum along the motion, then the constraint."""
    dq3, ddq3 = sm.Symbol("dq3"), sm.Symbol("ddq3")
    q1, q2 = kin.q[0], kin.q[1]
    dq = (dq_m[0], dq_m[1], dq3)
    ddq = (ddq_m[0], ddq_m[1], ddq3)
    Ldot = angular_momentum_rate(sm, kin, I3, dq, ddq)
    rhs = support_moment(sm, kin, k_t, d_t, dq) + moment
    dq3_expr = con.s[2] + con.S[2, 0] * dq_m[0] + con.S[2, 1] * dq_m[1]
    ddq3_expr = (dq3_expr.diff(q1) * dq_m[0] + dq3_expr.diff(q2) * dq_m[1]
                 + dq3_expr.diff(dq_m[0]) * ddq_m[0] + dq3_expr.diff(dq_m[1]) * ddq_m[1])
    res = (Ldot - rhs).subs({ddq3: ddq3_expr}).subs({dq3: dq3_expr})
    return sm.Matrix([res[0], res[1]])
