"""Symbols and units of parameters and quantities for figures: one table for every plot.

Parameter names follow the paper (``mu1``, ``k_ip``, ``h10``, ``Omega``); their
symbols are derived by one rule (Greek names become Greek letters, trailing
digits and underscore parts become subscripts), units come from the model's
roles (:mod:`brakesqueal.model.roles`) through :func:`unit`.

>>> symbol("k_ip1")
'k_{\\\\mathrm{ip}1}'
>>> axis_label("Omega", "rad/s")
'$\\\\Omega$ [rad/s]'
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from matplotlib.typing import RcKeyType

    from .model.parameters import ParameterSpace

__all__ = ["symbol", "axis_label", "unit", "branch_status_text", "QUANTITIES", "STYLE",
           "BRANCH_STATUS_TEXT"]

_GREEK = {"alpha", "beta", "gamma", "delta", "epsilon", "zeta", "eta", "theta", "iota", "kappa", "lambda", "mu",
          "nu", "xi", "pi", "rho", "sigma", "tau", "phi", "chi", "psi", "omega", "Gamma", "Delta", "Theta",
          "Lambda", "Xi", "Pi", "Sigma", "Phi", "Psi", "Omega"}

#: Symbols and units of computed quantities (variables of maps, paths and trajectories).
QUANTITIES: dict[str, tuple[str, str]] = {
    "max_real": (r"\max\,\mathrm{Re}\,\lambda", "1/s"),
    "frequency": (r"f", "Hz"),
    "growth_rate": (r"\sigma", "1/s"),
    "damping_ratio": (r"\zeta", ""),
    "Omega_crit": (r"\Omega_\mathrm{crit}", "rad/s"),
}

#: Units of the auxiliary names of the paper's presets (not parameters of the paper's model).
AUX_UNITS: dict[str, str] = {"mu": "", "k_ip": "N/m", "h": "m", "R_disk": "m"}

#: Matplotlib style of every figure: sizes for a single journal column (3.5 in), vector-friendly.
STYLE: dict[RcKeyType, object] = {
    "font.size": 8, "axes.labelsize": 8, "axes.titlesize": 8, "legend.fontsize": 7, "xtick.labelsize": 7,
    "ytick.labelsize": 7, "lines.linewidth": 1.0, "axes.linewidth": 0.6, "savefig.bbox": "tight",
    "pdf.fonttype": 42, "svg.fonttype": "none", "mathtext.fontset": "cm",
}


def _base(word: str) -> tuple[str, str]:
    m = re.fullmatch(r"([A-Za-z]+?)(\d*)", word)
    letters, digits = (m.group(1), m.group(2)) if m else (word, "")
    if letters in _GREEK:
        head = "\\" + letters
    elif len(letters) == 1:
        head = letters
    else:
        head = r"\mathrm{" + letters + "}"
    return head, digits


def symbol(name: str) -> str:
    """The mathtext symbol of a parameter or quantity name (without ``$``).

    Parameters
    ----------
    name : str
        E.g. ``"mu1"``, ``"k_ip"``, ``"N0"``, ``"Omega"``, ``"max_real"``.

    Returns
    -------
    str
        E.g. ``"\\mu_{1}"``, ``"k_{\\mathrm{ip}}"``, ``"N_{0}"``, ``"\\Omega"``.
    """
    if name in QUANTITIES:
        return QUANTITIES[name][0]
    first, *rest = name.split("_")
    head, digits = _base(first) if first else (name, "")
    sub = ""
    if rest:
        parts = []
        for w in rest:
            m = re.fullmatch(r"([A-Za-z]*)(\d*)", w)
            letters, d = (m.group(1), m.group(2)) if m else (w, "")
            parts.append((r"\mathrm{" + letters + "}" if letters else "") + d)
        sub = "".join(parts) + digits
    else:
        sub = digits
    return f"{head}_{{{sub}}}" if sub else head


def _unit_text(unit: str) -> str:
    return unit.replace("^2", "²").replace("^3", "³").replace("^-1", "⁻¹")


def axis_label(name: str, unit: str | None = None) -> str:
    """``"$symbol$ [unit]"`` (no brackets for dimensionless quantities).

    Parameters
    ----------
    name : str
        Parameter or quantity name.
    unit : str, optional
        SI unit (default: the quantity's own unit from :data:`QUANTITIES`, else none).

    Returns
    -------
    str
    """
    if unit is None:
        unit = QUANTITIES.get(name, ("", ""))[1]
    text = f"${symbol(name)}$"
    return f"{text} [{_unit_text(unit)}]" if unit else text


def unit(name: str, space: ParameterSpace | None = None) -> str:
    """SI unit of a settable name.

    Parameters
    ----------
    name : str
        A parameter or auxiliary name (``"mu"``, ``"k_ip1"``, ``"Omega"``).
    space : ParameterSpace, optional
        The space the name belongs to: its preset's model roles and
        auxiliary names decide; without it, the paper's model.

    Returns
    -------
    str
        The unit (``""`` for dimensionless or unknown names).
    """
    if space is not None:
        try:
            return str(space.preset.unit(name))
        except Exception:  # an auxiliary name without a unit
            return ""
    from .model.library import get_model

    spec = get_model("paper")
    return spec.unit(name) if name in spec.parameters else AUX_UNITS.get(name, "")


#: Why a limit-cycle branch ended, in words for figures and tables (the codes are the branches' ``status``).
BRANCH_STATUS_TEXT = {
    "max_points": "stopped at the point limit",
    "range": "end of the range reached",
    "contact_loss": "stopped where a pad loses contact",
    "sliding_reversal": "stopped where a pad's sliding reverses",
    "truncation": "stopped: more harmonics needed",
    "step_underflow": "stopped: the step became too small",
    "period": "stopped: the period grew beyond its limit",
    "equilibrium": "the cycle shrinks back to the silent motion",
}


def branch_status_text(status: str) -> str:
    """:data:`BRANCH_STATUS_TEXT` of a branch's ``status`` (an unknown code with its underscores as spaces)."""
    return BRANCH_STATUS_TEXT.get(status, status.replace("_", " "))
