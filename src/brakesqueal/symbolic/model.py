r"""Assembly of the nonlinear 2-DOF equations of the general wobbling-disk model.

:func:`derive_equations` runs the paper's procedure end to end:
kinematics (eqs. 2-11) → pad contacts (eqs. 12-34) → matrix Euler equations
(eqs. 35-38) → constraint elimination (eqs. 40-45), returning the residuals

* ``psi(x, p) = 0``  (2 equations of motion, eq. 44) and
* ``g(x, p) = 0``    (tangential equilibria of the massless pads, eqs. 33-34),

as functions of the state ``x = (q1, q2, dq1, dq2, ddq1, ddq2, l1, l2, dl1, dl2)``
and the parameters ``p`` of :data:`PARAMETER_SYMBOLS`.  Internally the
tangential stiffnesses enter as compliances ``c_ip = 1/k_ip`` so that a rigid
tangential support (``k_ip = inf``) is the regular value ``c_ip = 0``.

The pads are components (:class:`~.contact.PadSymbols`); the engine sums their
moments, so adding pads does not change it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from types import ModuleType
from typing import Any

from .backend import Backend, get_backend
from .constraint import ReducedEquations, reduce_equations, spin_constraint
from .contact_legacy import PadContact, PadSymbols, pad_contact
from .euler import angular_momentum_rate, euler_matrices, support_moment
from .kinematics import CardanKinematics, cardan_kinematics

__all__ = [
    "PARAMETER_SYMBOLS",
    "STATE_SYMBOLS",
    "SymbolicEquations",
    "derive_equations",
]

#: Order of the parameters in every symbolic and compiled function.
PARAMETER_SYMBOLS: tuple[str, ...] = (
    "Theta", "Phi", "k_t", "d_t", "k1", "k2", "d1", "d2", "c_ip1", "c_ip2",
    "mu1", "mu2", "h10", "h20", "r", "N0", "Omega",
)  # fmt: skip

#: Order of the state in every symbolic and compiled function.
STATE_SYMBOLS: tuple[str, ...] = ("q1", "q2", "dq1", "dq2", "ddq1", "ddq2", "l1", "l2", "dl1", "dl2")


@dataclass(frozen=True)
class SymbolicEquations:
    """Nonlinear equations of the 2-DOF model, in one symbolic backend.

    Attributes
    ----------
    psi : Matrix
        2 × 1 residual of eq. (44).
    g : Matrix
        2 × 1 residual of the pads' tangential equilibria (eqs. 33-34).
    reduced : ReducedEquations or None
        The matrices ``M_m, C_m, D_m, K_m, f_m`` of eq. (45); ``None`` when
        derived without Kronecker products (``kronecker=False``).
    pads : tuple of PadContact
        Contact quantities (constraint substituted).
    state : dict
        State symbols by the names of :data:`STATE_SYMBOLS`.
    params : dict
        Parameter symbols by the names of :data:`PARAMETER_SYMBOLS`.
    backend : str
        ``"symengine"`` or ``"sympy"``.
    kinematics : CardanKinematics
        Direction cosines, rotational Jacobians and Hessians of the disk
        (eqs. 2-11), with ``q3 = 0`` substituted unless derived with
        ``keep_q3=True``.
    """

    psi: Any
    g: Any
    reduced: ReducedEquations | None
    pads: tuple[PadContact, ...]
    state: dict[str, Any]
    params: dict[str, Any]
    backend: str
    kinematics: CardanKinematics = field(repr=False)

    @property
    def state_vector(self) -> list[Any]:
        """State symbols in :data:`STATE_SYMBOLS` order."""
        return [self.state[n] for n in STATE_SYMBOLS]

    @property
    def param_vector(self) -> list[Any]:
        """Parameter symbols in :data:`PARAMETER_SYMBOLS` order."""
        return [self.params[n] for n in PARAMETER_SYMBOLS]


def _symbols(sm: ModuleType) -> tuple[dict[str, Any], dict[str, Any]]:
    state = {n: sm.Symbol(n) for n in STATE_SYMBOLS}
    params = {n: sm.Symbol(n) for n in PARAMETER_SYMBOLS}
    return state, params


def derive_equations(
    backend: Backend = "symengine", *, kronecker: bool = True, keep_q3: bool = False
) -> SymbolicEquations:
    """Derive the nonlinear equations of the general asymmetric model.

    Parameters
    ----------
    backend : {"symengine", "sympy"}
        Computer-algebra backend.
    kronecker : bool
        ``True`` (default) uses the paper's matrix Euler equations with
        Kronecker products (eqs. 35-37, 44-45).  ``False`` differentiates the
        angular momentum along the motion with the chain rule and substitutes
        the constraint directly (the comparison route of the paper's 5 % claim).
    keep_q3 : bool
        Keep the spin angle ``q3`` as a symbol (it drops out of the equations
        of an axisymmetric disk; the tests use this to check that).  By default
        ``q3 = 0`` is substituted once the rotational Hessians are formed.

    Returns
    -------
    SymbolicEquations
    """
    sm = get_backend(backend)
    st, p = _symbols(sm)
    q3 = sm.Symbol("q3")
    dq3, ddq3 = sm.Symbol("dq3"), sm.Symbol("ddq3")
    q_m = (st["q1"], st["q2"])
    dq_m = (st["dq1"], st["dq2"])
    ddq_m = (st["ddq1"], st["ddq2"])
    kin = cardan_kinematics(sm, (q_m[0], q_m[1], q3))
    if not keep_q3:
        sub = {q3: sm.Integer(0)}
        kin = CardanKinematics(
            A=kin.A.subs(sub), A1=kin.A1, A2=kin.A2, J_R0=kin.J_R0, J_R3=kin.J_R3.subs(sub),
            H_R0=kin.H_R0, H_R3=kin.H_R3.subs(sub), q=kin.q,
        )  # fmt: skip
    I3 = sm.diag(p["Theta"], p["Theta"], p["Phi"])
    con = spin_constraint(sm, q_m, p["Omega"])
    qdot = con.s + con.S * sm.Matrix(list(dq_m))  # eq. (41)
    omega0 = kin.J_R0 * qdot  # eq. (6) with the constraint
    pads = _paper_pads(st, p)
    contacts = tuple(
        pad_contact(sm, pad, r=p["r"], N0=p["N0"], z3=kin.A[:, 2], omega0=omega0, q=q_m, dq=dq_m) for pad in pads
    )
    moment = sm.zeros(3, 1)
    for c in contacts:
        moment = moment + c.moment
    g = sm.Matrix([c.g for c in contacts])
    if kronecker:
        M0, Cstar0 = euler_matrices(sm, kin, I3)
        red = reduce_equations(sm, M0, Cstar0, con, q_m, dq_m, ddq_m, p["k_t"], p["d_t"], moment)
        psi = red.psi
    else:
        red = None
        psi = _psi_without_kronecker(sm, kin, I3, con, st, p, q3, dq3, ddq3, moment)
    return SymbolicEquations(
        psi=psi, g=g, reduced=red, pads=contacts, state=st, params=p, backend=backend, kinematics=kin
    )


def _paper_pads(st: dict[str, Any], p: dict[str, Any]) -> tuple[PadSymbols, PadSymbols]:
    """The paper's two pads: upper (index 1) and lower (index 2), both at ``y0 = -r``."""
    return (
        PadSymbols(side=1, k=p["k1"], d=p["d1"], c_ip=p["c_ip1"], mu=p["mu1"], h0=p["h10"], l=st["l1"], dl=st["dl1"]),
        PadSymbols(side=-1, k=p["k2"], d=p["d2"], c_ip=p["c_ip2"], mu=p["mu2"], h0=p["h20"], l=st["l2"], dl=st["dl2"]),
    )


def _psi_without_kronecker(sm, kin, I3, con, st, p, q3, dq3, ddq3, moment):  # type: ignore[no-untyped-def]
    """Classical route: chain-rule derivative of the angular momentum, then substitute."""
    q1, q2 = kin.q[0], kin.q[1]
    dq = (st["dq1"], st["dq2"], dq3)
    ddq = (st["ddq1"], st["ddq2"], ddq3)
    Ldot = angular_momentum_rate(sm, kin, I3, dq, ddq)
    rhs = support_moment(sm, kin, p["k_t"], p["d_t"], dq) + moment
    # constraint: q3dot from eq. (40), q3ddot by differentiating it along the motion
    dq3_expr = con.s[2] + con.S[2, 0] * st["dq1"] + con.S[2, 1] * st["dq2"]
    ddq3_expr = (
        dq3_expr.diff(q1) * st["dq1"] + dq3_expr.diff(q2) * st["dq2"]
        + dq3_expr.diff(st["dq1"]) * st["ddq1"] + dq3_expr.diff(st["dq2"]) * st["ddq2"]
    )  # fmt: skip
    res = (Ldot - rhs).subs({ddq3: ddq3_expr}).subs({dq3: dq3_expr})
    return sm.Matrix([res[0], res[1]])


@lru_cache(maxsize=4)
def cached_equations(backend: Backend = "symengine") -> SymbolicEquations:
    """In-process cache of :func:`derive_equations` with default options."""
    return derive_equations(backend)
