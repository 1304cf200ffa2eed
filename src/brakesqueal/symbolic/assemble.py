r"""Assembly of the nonlinear equations of any model (the paper's procedure, eqs. 2-45).

Each component carries its physics as hooks written next to its data in
:mod:`brakesqueal.model.components` (backend-neutral, like the friction laws'
formulas); :func:`build_equations` is the generic driver that calls them with
an :class:`Assembly` context, in a fixed order: the disk's kinematics
(Cardan angles, eqs. 2-11, with the spin constraint, eqs. 40-42), then the
pads (their contact, :mod:`.contact`, eqs. 12-34, and either the massless
relations of the paper or Newton's law for their mass), the calipers
(Newton's law for their translations) and any other kind, and last the
disk's matrix Euler equations with Kronecker products (eqs. 35-38) and the
elimination of the spin constraint (eqs. 43-45), with the moments summed
over the components.  :func:`energy_terms` sums the components' energy hooks.

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
from collections.abc import Callable, Container, Mapping
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING, Any

from ..model.components import components
from .backend import Backend, get_backend
from .constraint import ReducedEquations, SpinConstraint, reduce_equations, spin_constraint
from .contact import PadContact, angle_cos_sin, friction_coefficient, pad_contact
from .euler import angular_momentum_rate, euler_matrices, support_moment
from .kinematics import CardanKinematics, cardan_kinematics

if TYPE_CHECKING:
    from ..model.components import Component, FrictionLaw, ModelSpec

__all__ = ["Equations", "Assembly", "ENERGY_TERMS", "PHASES", "build_equations", "energy_terms",
           "compliance_name"]


def compliance_name(name: str, taken: Container[str] = ()) -> str:
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

    spec: ModelSpec
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
    backend: Backend

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


class _Values:
    """Component field → symbolic value (names → symbols, stiffness names → 1/compliance)."""

    def __init__(self, sm: ModuleType, spec: ModelSpec) -> None:
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


#: Names of the energy terms a component's ``energy`` hook may return (``docs/simulation.md``, energy).
ENERGY_TERMS = ("T2", "T1", "T0", "V_support", "V_pads")

#: The assembly hooks of a component, in the order :func:`build_equations` calls them (each over every component).
PHASES = ("prepare", "assemble", "finish")


class Assembly:
    """What a component's physics hooks see while a model is assembled (or its energy written).

    The hooks are methods of the component classes (:mod:`brakesqueal.model.components`, which
    import no computer algebra): ``coordinates()`` and ``deformations()`` name the component's
    coordinates ``Q`` and pad deformations ``L``; ``prepare(ctx)``, ``assemble(ctx)`` and
    ``finish(ctx)`` are called in that order, each for every component in
    :data:`~brakesqueal.model.components.COMPONENTS` order (the disk's kinematics are prepared
    first; its Euler equations are finished last, with the moments the other components added);
    ``energy(ctx)`` returns a component's terms of :data:`ENERGY_TERMS`.

    Attributes
    ----------
    sm : module
        The computer-algebra backend (``symengine`` or ``sympy``).
    spec : ModelSpec
        The model.
    val : callable
        ``val(field_value)``: a component field's symbolic value (a parameter name → its symbol, a
        tangential stiffness name → ``1/compliance``, a number → an exact number, ``None`` → 0);
        ``val.compliance(k_ip)`` is the compliance ``1/k_ip`` (0 for ``inf``).
    coords, algebraic : list of str
        Names of the coordinates ``Q`` and the pad deformations ``L``.
    Q, dQ, ddQ, L, dL : dict
        Their symbols by name (``dQ["q1"]`` is the symbol ``dq1``).
    engagement : mapping or None
        Pad name → factor of its contact force (unilateral contact), ``None``: every pad pressed.
    kronecker, keep_q3 : bool
        Options of :func:`build_equations`.
    Omega, omega0, z3 : expression, Matrix, Matrix
        Spin rate, angular velocity of the disk and its axis in the fixed frame (set by
        :meth:`disk_kinematics`).
    kinematics, constraint, qdot
        :class:`~.kinematics.CardanKinematics`, :class:`~.constraint.SpinConstraint` and
        ``qdot = s + S q_mdot`` (eq. 41) of a tilting disk (``None`` otherwise).
    rows : dict
        Residual row of each coordinate (Newton's law ``M qddot - F = 0``), summed by :meth:`add_row`.
    G_rows : list
        Residuals ``G`` of the pads' tangential balances, in ``L`` order.
    moment : Matrix
        Sum of the moments about O acting on the disk (fixed frame; the contact moments of eq. 38).
    contacts, tangential : dict
        Per pad name, its :class:`~.contact.PadContact` and tangential position ``l`` (the
        ``Equations.pads`` and ``Equations.tangential``, in pad order).
    reduced : ReducedEquations or None
        The disk's matrices of eq. (45) (set by :meth:`euler_rows` on the Kronecker route).
    """

    def __init__(self, sm: ModuleType, spec: ModelSpec, coords: list[str], algebraic: list[str], *,
                 kronecker: bool = True, keep_q3: bool = False, engagement: Mapping[str, Any] | None = None) -> None:
        self.sm = sm
        self.spec = spec
        self.val = _Values(sm, spec)
        self.coords, self.algebraic = coords, algebraic
        self.Q = {n: sm.Symbol(n) for n in coords}
        self.dQ = {n: sm.Symbol(f"d{n}") for n in coords}
        self.ddQ = {n: sm.Symbol(f"dd{n}") for n in coords}
        self.L = {n: sm.Symbol(n) for n in algebraic}
        self.dL = {n: sm.Symbol(f"d{n}") for n in algebraic}
        self.engagement = engagement
        self.kronecker, self.keep_q3 = kronecker, keep_q3
        self.Omega: Any = None
        self.omega0: Any = None
        self.z3: Any = None
        self.kinematics: CardanKinematics | None = None
        self.constraint: SpinConstraint | None = None
        self.qdot: Any = None
        self.rows: dict[str, Any] = {}
        self.G_rows: list[Any] = []
        self.moment = sm.zeros(3, 1)
        self.contacts: dict[str, PadContact] = {}
        self.tangential: dict[str, Any] = {}
        self.reduced: ReducedEquations | None = None

    @classmethod
    def of(cls, eq: Equations) -> Assembly:
        """The context of assembled equations (for the ``energy`` hooks): symbols, disk kinematics, pad contacts."""
        ctx = cls(get_backend(eq.backend), eq.spec, list(eq.coords), list(eq.algebraic))
        ctx.Q, ctx.dQ, ctx.ddQ = (dict(zip(eq.coords, x)) for x in (eq.Q, eq.dQ, eq.ddQ))
        ctx.L, ctx.dL = dict(zip(eq.algebraic, eq.L)), dict(zip(eq.algebraic, eq.dL))
        ctx.kinematics, ctx.qdot, ctx.reduced = eq.kinematics, eq.constraint_qdot, eq.reduced
        ctx.contacts = {p.name: c for p, c in zip(eq.spec.pads, eq.pads)}
        ctx.tangential = {p.name: t for p, t in zip(eq.spec.pads, eq.tangential)}
        return ctx

    def rate(self, e: Any) -> Any:
        """Time derivative of an expression of ``Q`` and ``L`` along the motion."""
        out = self.sm.Integer(0)
        for n in self.coords:
            out += e.diff(self.Q[n]) * self.dQ[n]
        for n in self.algebraic:
            out += e.diff(self.L[n]) * self.dL[n]
        return out

    def add_row(self, coordinate: str, expr: Any) -> None:
        """Add ``expr`` to the residual row of a coordinate (a generalized force enters with a minus sign)."""
        self.rows[coordinate] = self.rows[coordinate] + expr if coordinate in self.rows else expr

    def angle_cos_sin(self, deg: float) -> tuple[Any, Any]:
        """Exact ``cos``/``sin`` of an angle in degrees (:func:`.contact.angle_cos_sin`)."""
        return angle_cos_sin(self.sm, deg)

    def friction(self, law: FrictionLaw, v: Any) -> Any:
        """``mu(v)`` of a :class:`~brakesqueal.model.components.FrictionLaw` (its fields through :attr:`val`)."""
        return friction_coefficient(self.sm, law, v, self.val)

    def pad_contact(self, **kw: Any) -> PadContact:
        """A pad's contact quantities (paper eqs. 12-34): :func:`.contact.pad_contact` with this backend,
        the disk's ``z3``, ``omega0`` and :meth:`rate`; the other keywords are those of that function."""
        return pad_contact(self.sm, z3=self.z3, omega0=self.omega0, rate=self.rate, **kw)

    def disk_kinematics(self, Omega: Any, tilt: tuple[str, str] | None) -> None:
        """Set the disk's kinematics: spin rate ``Omega``, angular velocity ``omega0``, axis ``z3``.

        ``tilt``: the names of the tilt coordinates ``(q1, q2)`` (Cardan kinematics, eqs. 2-11, with the
        spin constraint eqs. 40-42 substituted), or ``None`` for a disk spinning about ``z0``.
        """
        sm = self.sm
        self.Omega = Omega
        if tilt is None:
            self.z3 = sm.Matrix([0, 0, 1])
            self.omega0 = self.z3 * Omega
            return
        q_m = (self.Q[tilt[0]], self.Q[tilt[1]])
        q3 = sm.Symbol("q3")
        kin = cardan_kinematics(sm, (q_m[0], q_m[1], q3))
        if not self.keep_q3:
            sub = {q3: sm.Integer(0)}
            kin = CardanKinematics(A=kin.A.subs(sub), A1=kin.A1, A2=kin.A2, J_R0=kin.J_R0,
                                   J_R3=kin.J_R3.subs(sub), H_R0=kin.H_R0, H_R3=kin.H_R3.subs(sub), q=kin.q)
        con = spin_constraint(sm, q_m, Omega)
        self.kinematics, self.constraint = kin, con
        self.qdot = con.s + con.S * sm.Matrix([self.dQ[tilt[0]], self.dQ[tilt[1]]])  # eq. (41)
        self.omega0 = kin.J_R0 * self.qdot  # eq. (6) with the constraint
        self.z3 = kin.A[:, 2]

    def euler_rows(self, tilt: tuple[str, str], I3: Any, k_t: Any, d_t: Any) -> Any:
        """The disk's two residual rows (eq. 44) with the summed :attr:`moment` (Kronecker route or chain rule).

        ``I3``: inertia tensor in the body frame; ``k_t``, ``d_t``: rotational supports (eq. 45).
        """
        sm, kin, con = self.sm, self.kinematics, self.constraint
        assert kin is not None and con is not None, "disk_kinematics() sets the tilt kinematics first"
        q_m = (self.Q[tilt[0]], self.Q[tilt[1]])
        dq_m, ddq_m = (self.dQ[tilt[0]], self.dQ[tilt[1]]), (self.ddQ[tilt[0]], self.ddQ[tilt[1]])
        if self.kronecker:
            M0, Cstar0 = euler_matrices(sm, kin, I3)
            self.reduced = reduce_equations(sm, M0, Cstar0, con, q_m, dq_m, ddq_m, k_t, d_t, self.moment)
            return self.reduced.psi
        return _psi_without_kronecker(sm, kin, I3, con, dq_m, ddq_m, k_t, d_t, self.moment)


def build_equations(spec: ModelSpec, backend: Backend = "symengine", *, kronecker: bool = True,
                    keep_q3: bool = False, engagement: Mapping[str, Any] | None = None) -> Equations:
    """Assemble the nonlinear equations of a model from its components' physics hooks.

    The driver of :class:`Assembly`: every component names its coordinates and pad deformations, then
    the hooks ``prepare`` (the disk's kinematics), ``assemble`` (pads, calipers, other kinds: forces,
    rows, moments on the disk) and ``finish`` (the disk's Euler equations, eqs. 35-45) run in that
    order, each over every component in :data:`~brakesqueal.model.components.COMPONENTS` order.

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

    Raises
    ------
    ValueError
        If a component names a coordinate that no hook gives a residual row.
    """
    sm = get_backend(backend)
    parts = [comp for _, comp in components(spec)]
    coords = [n for comp in parts for n in _hook(comp, "coordinates", lambda: ())()]
    algebraic = [n for comp in parts for n in _hook(comp, "deformations", lambda: ())()]
    ctx = Assembly(sm, spec, coords, algebraic, kronecker=kronecker, keep_q3=keep_q3, engagement=engagement)
    for phase in PHASES:
        for comp in parts:
            _hook(comp, phase, lambda ctx: None)(ctx)
    missing = [n for n in coords if n not in ctx.rows]
    if missing:
        raise ValueError(f"model '{spec.name}': no residual row for coordinate(s) {', '.join(missing)}")
    R = sm.Matrix([ctx.rows[n] for n in coords])
    G = sm.Matrix(ctx.G_rows) if ctx.G_rows else None
    val = ctx.val
    return Equations(
        spec=spec, coords=tuple(coords), algebraic=tuple(algebraic), R=R, G=G, Q=[ctx.Q[n] for n in coords],
        dQ=[ctx.dQ[n] for n in coords], ddQ=[ctx.ddQ[n] for n in coords], L=[ctx.L[n] for n in algebraic],
        dL=[ctx.dL[n] for n in algebraic], params=[val.sym[n] for n in spec.parameters],
        param_names=tuple(val.pname[n] for n in spec.parameters), pads=tuple(ctx.contacts.values()),
        tangential=tuple(ctx.tangential.values()), reduced=ctx.reduced, kinematics=ctx.kinematics,
        constraint_qdot=ctx.qdot, backend=backend,
    )  # fmt: skip


def energy_terms(eq: Equations) -> dict[str, Any]:
    """The energy of a model's motion, summed over its components' ``energy`` hooks.

    Parameters
    ----------
    eq : Equations
        The model's assembled equations.

    Returns
    -------
    dict
        Every name of :data:`ENERGY_TERMS` → its expression (kinetic energy by degree in the tilt rates
        ``T2, T1, T0``; potentials ``V_support`` of supports and ``V_pads`` of pad springs and preloads).

    Raises
    ------
    ValueError
        If a hook returns a term that is not one of :data:`ENERGY_TERMS`.
    """
    ctx = Assembly.of(eq)
    total = {k: ctx.sm.Integer(0) for k in ENERGY_TERMS}
    for _, comp in components(eq.spec):
        for k, v in _hook(comp, "energy", lambda ctx: {})(ctx).items():
            if k not in total:
                raise ValueError(f"{type(comp).__name__}.energy returned '{k}'; the terms are "
                                 f"{', '.join(ENERGY_TERMS)}")
            total[k] += v
    return total


def _hook(comp: Component, name: str, default: Callable[..., Any]) -> Callable[..., Any]:
    """A component's physics hook, or ``default`` when its class defines none (a kind with data only)."""
    return getattr(comp, name, None) or default


def _psi_without_kronecker(sm: ModuleType, kin: CardanKinematics, I3: Any, con: SpinConstraint, dq_m: Any,
                           ddq_m: Any, k_t: Any, d_t: Any, moment: Any) -> Any:
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
