"""Export any model as code: C, GNU Octave/MATLAB, Julia, Python and LaTeX.

:func:`export_code` prints, for any
:class:`~brakesqueal.model.components.ModelSpec` (the paper's 2-DOF model,
the built models, TOML models), either the nonlinear equations (residuals
``R``, ``G``, the pad solver, a right-hand side for ODE solvers) or the
closed-form linear matrices ``M, D, K`` about the zero state, with SymPy's
code printers and common subexpressions eliminated (:func:`sympy.cse`).
Every output starts with a header listing the argument order and units
(:mod:`.model` describes the layout).  ``brakesqueal export`` is the
command-line front end.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal

from .model import WHATS, ExportFunction, ExportModel, export_model

if TYPE_CHECKING:
    from ..model.components import ModelSpec
    from ..model.parameters import Parameters

__all__ = ["TARGETS", "WHATS", "ExportFunction", "ExportModel", "export_code", "export_model", "check_name"]

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
    model: ModelSpec | str | None = None,
) -> str:
    """Source code (or a LaTeX document) of a model.

    Parameters
    ----------
    target : {"latex", "octave", "c", "julia", "python"}
        Output language; see :mod:`brakesqueal.export.printers` for the
        conventions of each.
    what : {"nonlinear", "linear"}
        ``"nonlinear"``: functions ``residuals(x, p)``,
        ``pad_residuals(y, l, p)`` and ``pad_residual_scale(y, l, p)``
        (models with pad deformations), ``mass_force(y, l, p)``,
        ``solve_pads(y, p)``, ``state_derivative(y, l, p)``,
        ``rhs(t, y, p)``; ``"linear"``: ``linear_matrices(p)``, the closed
        form about the zero state.  Both add ``parameters()``.
    params : Parameters, optional
        Parameter set returned by the exported ``parameters()``; it names
        the model (default: the default preset of ``model``, or preset
        ``paper-fig2``).  With ``what="linear"`` the zero state must be its
        silent motion (for the paper's model eq. 49).
    name : str
        Stem of the output file; the Octave main function is given this name.
    source : str, optional
        Description of where ``params`` came from, for the header.
    model : ModelSpec or str, optional
        The model, when ``params`` is not given (built-in name or TOML path).

    Returns
    -------
    str
        The complete file contents.

    Raises
    ------
    ParameterError
        For an unknown ``target`` or ``what``, a ``name`` that is not an
        identifier, or ``what="linear"`` where the zero state is not the
        silent motion.
    """
    from ..errors import ParameterError
    from .printers import PRINTERS

    if target not in TARGETS:
        raise ParameterError(f"The option '--to' must be one of {', '.join(TARGETS)}; got {target!r}")
    check_name(name, target)
    desc = export_model(what, params, source=source, model=model)
    if target == "latex":
        from .latex import print_latex

        return print_latex(desc, name)
    return PRINTERS[target](desc, name)


def check_name(name: str, target: str) -> None:
    """Raise :class:`~brakesqueal.errors.ParameterError` unless ``name`` can name the ``target`` module.

    Parameters
    ----------
    name : str
        Stem of the output file.
    target : str
        Output language.
    """
    from ..errors import ParameterError
    from .names import is_identifier

    if not is_identifier(name):
        raise ParameterError(
            f"The output file name must be an identifier (letters, digits, '_', starting with a letter) so that "
            f"it can name the {target} module; got {name!r}"
        )
