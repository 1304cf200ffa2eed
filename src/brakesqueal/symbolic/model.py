r"""The paper's 2-DOF model seen through its classic names (a view of :mod:`.assemble`).

:func:`derive_equations` assembles the built-in model ``paper`` with the one
engine of :func:`~brakesqueal.symbolic.assemble.build_equations` (eqs. 2-45)
and exposes it with the names of the paper:

* ``psi(x, p) = 0`` (2 equations of motion, eq. 44) and
* ``g(x, p) = 0`` (tangential equilibria of the massless pads, eqs. 33-34),

as functions of the state ``x = (q1, q2, dq1, dq2, ddq1, ddq2, l1, l2, dl1, dl2)``
and the parameters ``p`` of :data:`PARAMETER_SYMBOLS` (tangential stiffnesses
as compliances ``c_ip = 1/k_ip``, so that a rigid support is ``c_ip = 0``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

from .assemble import Equations, build_equations
from .backend import Backend
from .constraint import ReducedEquations
from .contact import PadContact
from .kinematics import CardanKinematics

__all__ = ["PARAMETER_SYMBOLS", "STATE_SYMBOLS", "SymbolicEquations", "derive_equations", "cached_equations"]

#: Order of the parameters in every symbolic and compiled function of the paper's model.
PARAMETER_SYMBOLS: tuple[str, ...] = (
    "Theta", "Phi", "k_t", "d_t", "k1", "k2", "d1", "d2", "c_ip1", "c_ip2",
    "mu1", "mu2", "h10", "h20", "r", "N0", "Omega",
)  # fmt: skip

#: Order of the state of the paper's model (``l1, l2`` are the assembly's ``l_1, l_2``).
STATE_SYMBOLS: tuple[str, ...] = ("q1", "q2", "dq1", "dq2", "ddq1", "ddq2", "l1", "l2", "dl1", "dl2")


@dataclass(frozen=True)
class SymbolicEquations:
    """Nonlinear equations of the paper's 2-DOF model.

    Attributes
    ----------
    psi : Matrix
        2 × 1 residual of eq. (44).
    g : Matrix
        2 × 1 residual of the pads' tangential equilibria (eqs. 33-34).
    reduced : ReducedEquations or None
        The matrices ``M_m, C_m, D_m, K_m, f_m`` of eq. (45); ``None`` when
        derived without Kronecker products.
    pads : tuple of PadContact
        Contact quantities (constraint substituted).
    state : dict
        State symbols by the names of :data:`STATE_SYMBOLS`.
    params : dict
        Parameter symbols by the names of :data:`PARAMETER_SYMBOLS`.
    backend : str
        ``"symengine"`` or ``"sympy"``.
    kinematics : CardanKinematics
        Direction cosines, rotational Jacobians and Hessians (eqs. 2-11).
    equations : Equations
        The general assembly this view is taken from.
    """

    psi: Any
    g: Any
    reduced: ReducedEquations | None
    pads: tuple[PadContact, ...]
    state: dict[str, Any]
    params: dict[str, Any]
    backend: str
    kinematics: CardanKinematics | None = field(repr=False)
    equations: Equations = field(repr=False)

    @property
    def state_vector(self) -> list[Any]:
        """State symbols in :data:`STATE_SYMBOLS` order."""
        return [self.state[n] for n in STATE_SYMBOLS]

    @property
    def param_vector(self) -> list[Any]:
        """Parameter symbols in :data:`PARAMETER_SYMBOLS` order."""
        return [self.params[n] for n in PARAMETER_SYMBOLS]


def derive_equations(backend: Backend = "symengine", *, kronecker: bool = True,
                     keep_q3: bool = False) -> SymbolicEquations:
    """Derive the nonlinear equations of the paper's general asymmetric model.

    Parameters
    ----------
    backend : {"symengine", "sympy"}
        Computer-algebra backend.
    kronecker : bool
        ``True`` (default) uses the matrix Euler equations with Kronecker
        products (eqs. 35-37, 44-45); ``False`` the chain-rule route.
    keep_q3 : bool
        Keep the spin angle ``q3`` as a symbol (default: ``q3 = 0``).

    Returns
    -------
    SymbolicEquations
    """
    from ..model.library import get_model

    eq = build_equations(get_model("paper"), backend, kronecker=kronecker, keep_q3=keep_q3)
    names = dict(zip(STATE_SYMBOLS, eq.x))
    return SymbolicEquations(psi=eq.R, g=eq.G, reduced=eq.reduced, pads=eq.pads, state=names,
                             params=dict(zip(eq.param_names, eq.params)), backend=backend,
                             kinematics=eq.kinematics, equations=eq)


@lru_cache(maxsize=4)
def cached_equations(backend: Backend = "symengine") -> SymbolicEquations:
    """In-process cache of :func:`derive_equations` with default options."""
    return derive_equations(backend)
