"""Export the model as code: C, GNU Octave/MATLAB, Julia, Python and LaTeX.

:func:`export_code` prints the nonlinear equations of motion with the spin
constraint eliminated (residuals ``psi``, pad residuals ``g``, a right-hand side
for ODE solvers) or the closed-form linear matrices ``Mbar, Dbar, Kbar`` about
the trivial silent motion, with SymPy's code printers and common
subexpressions eliminated (:func:`sympy.cse`).  Every output starts with a
header listing the argument order and units.  ``brakesqueal export`` is the
command-line front end.
"""

from __future__ import annotations

from typing import Literal

from ..parameters import Parameters
from .model import WHATS, ExportFunction, ExportModel, export_model

__all__ = ["TARGETS", "WHATS", "ExportFunction", "ExportModel", "export_code", "export_model"]

Target = Literal["latex", "octave", "c", "julia", "python"]
#: Export targets and the file suffix each one uses.
TARGETS: dict[str, str] = {"latex": ".tex", "octave": ".m", "c": ".c", "julia": ".jl", "python": ".py"}


def export_code(
    target: Target,
    what: Literal["nonlinear", "linear"] = "nonlinear",
    params: Parameters | None = None,
    *,
    name: str = "brakesqueal_model",
    source: str | None = None,
) -> str:
    """Source code (or a LaTeX document) of the model.

    Parameters
    ----------
    target : {"latex", "octave", "c", "julia", "python"}
        Output language; see :mod:`brakesqueal.export.printers` for the
        conventions of each.
    what : {"nonlinear", "linear"}
        ``"nonlinear"``: functions ``residuals(x, p)``,
        ``pad_residuals(y, l, p)``, ``state_derivative(y, l, p)``,
        ``solve_pads(y, p)``, ``rhs(t, y, p)``; ``"linear"``:
        ``linear_matrices(p)``, the closed form about the trivial silent
        motion.  Both add ``parameters()``.
    params : Parameters, optional
        Parameter set returned by the exported ``parameters()`` (default:
        preset ``paper-fig2``).  With ``what="linear"`` its silent motion
        must be trivial (eq. 49).
    name : str
        Stem of the output file; the Octave main function is given this name.
    source : str, optional
        Description of where ``params`` came from, for the header.

    Returns
    -------
    str
        The complete file contents.

    Raises
    ------
    ParameterError
        For an unknown ``target`` or ``what``, a ``name`` that is not an
        identifier, or ``what="linear"`` with a non-trivial silent motion.
    """
    from ..errors import ParameterError
    from .printers import PRINTERS, is_identifier

    if target not in TARGETS:
        raise ParameterError(f"The option '--to' must be one of {', '.join(TARGETS)}; got {target!r}")
    if not is_identifier(name):
        raise ParameterError(
            f"The output file name must be an identifier (letters, digits, '_', starting with a letter) so that "
            f"it can name the {target} module; got {name!r}"
        )
    model = export_model(what, params, source=source)
    if target == "latex":
        from .latex import print_latex

        return print_latex(model, name)
    return PRINTERS[target](model, name)
