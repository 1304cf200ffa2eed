"""Source printers for C, GNU Octave / MATLAB, Julia and Python (via :mod:`sympy.printing`).

Each printer formats an :class:`~.model.ExportModel`: the header (argument
order, units), one function per :class:`~.model.ExportFunction` (common
subexpressions first, then the outputs), the small hand-written helpers of
the nonlinear export (``solve_pads``, ``state_derivative``, ``rhs`` and a
linear solve) and ``parameters()``.  Conventions per language:

* **C** (:mod:`.c`, C99, ``#include <math.h>``, link with ``-lm``): functions
  ``brakesqueal_<name>(const double *in..., double *out...)``; matrices
  row-major; ``solve_pads``, ``state_derivative`` and ``rhs`` return 0 on
  success; a small Gaussian elimination solves ``M Qddot = -f``.
* **Octave** (:mod:`.octave`, also MATLAB): one function file; its main
  function, named after the file, returns a struct of function handles
  (``m = name(); m.rhs(t, y, p)``); inputs and outputs are column vectors,
  matrices ``rows × columns``; ``\\`` solves.
* **Julia** (:mod:`.julia`): ``module BrakesquealModel``; vectors are
  1-based, matrices ``Matrix``; ``\\`` solves.
* **Python** (:mod:`.python`): a dependency-free module (``math`` only);
  tuples out (matrices as tuples of rows); a hand-written solve.
"""

from __future__ import annotations

from typing import Callable

from .c import print_c
from .julia import print_julia
from .model import ExportModel
from .names import is_identifier
from .octave import print_octave
from .python import print_python

__all__ = ["print_c", "print_octave", "print_julia", "print_python", "PRINTERS", "is_identifier"]

#: Printer of each code target.
PRINTERS: dict[str, Callable[[ExportModel, str], str]] = {
    "c": print_c,
    "octave": print_octave,
    "julia": print_julia,
    "python": print_python,
}
