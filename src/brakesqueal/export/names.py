"""Names, units and labels of the exported arguments and outputs (no computer algebra).

* State units follow the coordinate kind: ``q...`` (disk tilt) in rad, every
  other coordinate (``w``, ``u``, ``wc``, ``uc``) and pad deformation ``l`` in m;
  rates and accelerations add ``/s`` and ``/s^2``.
* Parameter units come from the model (:meth:`ModelSpec.unit
  <brakesqueal.model.components.ModelSpec.unit>`); a tangential stiffness
  ``k_ip`` is packed as its compliance ``c_ip = 1/k_ip`` in m/N.
* Residual rows: a tilt equation is a moment (N m), a translation a force
  (N), a pad's tangential balance a length (m, eqs. 33-34).
* Every name becomes a local variable of the exported functions; a name that
  is a keyword or a library function of one of the target languages (or
  clashes with a generated name) gets a local alias (:func:`local_names`).
"""

from __future__ import annotations

import keyword
import re
from collections.abc import Iterable

from ..model.components import coordinate_unit

__all__ = ["RESERVED", "local_names", "coordinate_unit", "rate_unit", "residual_label", "residual_unit",
           "is_identifier", "latex_symbol"]

_IDENT = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")

_C = """auto break case char const continue default do double else enum extern float for goto if inline int long
register restrict return short signed sizeof static struct switch typedef union unsigned void volatile while
_Bool _Complex _Imaginary bool true false NULL EOF errno main
sin cos tan asin acos atan atan2 sinh cosh tanh asinh acosh atanh exp exp2 expm1 log log2 log10 log1p pow sqrt
cbrt hypot fabs floor ceil round trunc fmod fmin fmax fma erf erfc tgamma lgamma gamma isfinite isnan isinf
j0 j1 jn y0 y1 yn signbit copysign nan NAN INFINITY HUGE_VAL M_PI M_E""".split()
_OCTAVE = """break case catch classdef continue do else elseif end end_try_catch end_unwind_protect endclassdef
endenumeration endevents endfor endfunction endif endmethods endparfor endproperties endswitch endwhile
enumeration events for function global if methods otherwise parfor persistent properties return switch try
until unwind_protect unwind_protect_cleanup while pi e i j I J Inf inf NaN nan NA eps ans abs sign exp log
sqrt sin cos tan asin acos atan atan2 sinh cosh tanh power mod rem floor ceil zeros ones error reshape all any
isfinite numel rows columns disp printf""".split()
_JULIA = """baremodule begin break catch const continue do else elseif end export false finally for function
global if import let local macro module quote return struct true try using while abstract mutable primitive
type where in isa pi im Inf NaN abs sign exp log sqrt sin cos tan asin acos atan sinh cosh tanh zeros error
all isfinite length Float64 Int Matrix Vector""".split()
_PYTHON = """math abs pow float int range len tuple list min max all any sum print ArithmeticError
ValueError True False None""".split()
#: Names no exported local variable may take (keywords and library names of C, Octave, Julia and Python).
RESERVED: frozenset[str] = frozenset([*_C, *_OCTAVE, *_JULIA, *_PYTHON, *keyword.kwlist])


def is_identifier(name: str) -> bool:
    """Whether ``name`` is a valid function/file/variable name in every target language (ASCII, no leading ``_``)."""
    return bool(_IDENT.match(name))


def local_names(names: Iterable[str], taken: Iterable[str] = ()) -> dict[str, str]:
    """Local variable name of every input entry: the name itself where that is safe, else an alias.

    Parameters
    ----------
    names : iterable of str
        Entry names (coordinates, rates, pad deformations, parameters).
    taken : iterable of str
        Further names the locals must not take (arguments, outputs, temporaries).

    Returns
    -------
    dict
        ``{name: local}``; ``local == name`` unless ``name`` is reserved
        (:data:`RESERVED`), not a portable identifier, or clashes.
    """
    names = list(dict.fromkeys(names))
    used = set(RESERVED) | set(taken)
    keep = {n for n in names if is_identifier(n) and n not in used}
    used |= keep
    out: dict[str, str] = {}
    for k, n in enumerate(names):
        if n in keep:
            out[n] = n
            continue
        base = re.sub(r"[^A-Za-z0-9_]", "_", n).strip("_") or f"v{k}"
        if not base[0].isalpha():
            base = "v" + base
        cand, i = base + "_", 1
        while cand in used or not is_identifier(cand):
            cand, i = f"{base}_{i}", i + 1
        used.add(cand)
        out[n] = cand
    return out




def rate_unit(name: str, order: int) -> str:
    """Unit of the ``order``-th time derivative of a coordinate (``rad/s``, ``m/s^2``)."""
    base = coordinate_unit(name)
    return base if order == 0 else (f"{base}/s" if order == 1 else f"{base}/s^{order}")


def residual_label(name: str) -> str:
    """Label of a residual row: ``psi1`` for tilt ``q1`` (eq. 44), ``g1`` for ``l1`` (eqs. 33-34), ``R_w1`` else."""
    if name.startswith("q"):
        return "psi" + name[1:]
    if name.startswith("l"):
        return "g" + name[1:]
    return "R_" + name


def residual_unit(name: str) -> str:
    """Unit of the residual row of a coordinate or pad deformation (N m, N or m)."""
    if name.startswith("q"):
        return "N m"
    return "m" if name.startswith("l") else "N"


_GREEK = {"Theta", "Phi", "Omega", "mu", "theta", "phi", "omega", "alpha", "beta", "gamma", "delta", "epsilon",
          "kappa", "lambda", "nu", "rho", "sigma", "tau", "xi", "eta", "zeta", "chi", "psi", "Psi", "Gamma",
          "Delta", "Lambda", "Sigma", "Xi", "Pi"}


def latex_symbol(name: str) -> str:
    r"""LaTeX of a variable name: ``mu1`` → ``\mu_{1}``, ``k_ip1`` → ``k_{ip1}``, ``w_upper`` → ``w_{upper}``.

    Parameters
    ----------
    name : str
        A coordinate (``q1``, ``w_upper``), a pad deformation (``l1``) or a
        parameter (rates are written by the caller as ``\dot{...}``).

    Returns
    -------
    str
        Math-mode LaTeX.
    """
    m = re.match(r"^([A-Za-z]+?)(\d+)$", name)
    if "_" in name:
        head, _, tail = name.partition("_")
    elif m:
        head, tail = m.group(1), m.group(2)
    else:
        head, tail = name, ""
    head_tex = "\\" + head if head in _GREEK else (head if len(head) == 1 else r"\mathrm{" + head + "}")
    tail_tex = tail.replace("_", r"\_")
    return head_tex + (f"_{{{tail_tex}}}" if tail else "")
