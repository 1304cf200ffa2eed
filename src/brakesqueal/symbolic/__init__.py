"""Symbolic layer (SymPy/symengine only): kinematics, contacts, Euler equations, constraint, linearization."""

from .linearize import CASES, ClosedForm, closed_form, jacobian_blocks, linear_matrices, trivial_blocks
from .model import PARAMETER_SYMBOLS, STATE_SYMBOLS, SymbolicEquations, derive_equations

__all__ = [
    "CASES",
    "ClosedForm",
    "closed_form",
    "jacobian_blocks",
    "linear_matrices",
    "trivial_blocks",
    "PARAMETER_SYMBOLS",
    "STATE_SYMBOLS",
    "SymbolicEquations",
    "derive_equations",
]
