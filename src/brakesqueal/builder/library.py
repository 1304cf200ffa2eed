"""Built-in models, each with its assumptions and the reference it follows.

=====================  ====  ==============================================================
name                   DOF   what
=====================  ====  ==============================================================
``paper-2dof``         2     the paper's general asymmetric model (massless pads)
``minimal``            2     eq. (54)/(55), the minimal model of the paper's ref. [6]
``in-plane-pad``       2     the paper's ref. [7]: tangential springs, no dampers, symmetric
``six-dof``            6     pads with mass moving normal and tangential (after ref. [5])
``eight-dof``          8     ``six-dof`` with a floating caliper (normal + tangential), after ref. [8]
``four-pad``           2     four equal pads at 0, 90, 180, 270 degrees on the upper face
``belt``               1     a pad mass on the spinning, non-tilting disk (a mass on a belt)
=====================  ====  ==============================================================

The exact published forms of refs. [5] and [8] are not available to this
project; ``six-dof`` and ``eight-dof`` are built in their spirit from the
stated DOF counts (assumptions in ``docs/model-builder.md``).
"""

from __future__ import annotations

import math

from ..errors import ParameterError
from .components import Caliper, Disk, FrictionLaw, ModelSpec, Pad

__all__ = ["MODELS", "get_model", "paper_parameters"]


def paper_parameters() -> dict[str, float]:
    """The paper's parameter values (Sec. 3.1, Fig. 2 at mu = 0.5, k_ip = 1e8)."""
    return {
        "Theta": 0.16, "Phi": 0.32, "k_t": 1.88e7, "d_t": 0.1, "h10": 0.01, "h20": 0.01,
        "Omega": 16 * math.pi,
    }  # fmt: skip


def _paper_pads(*, kip: bool = True, mass: bool = False, mount: str | None = None) -> tuple[Pad, Pad]:
    extra: dict = {}
    if mass:
        extra = {"mass": "m_p", "dofs": ("normal", "tangential"), "k_c": "k_c", "d_c": "d_c", "d_ip": "d_ip"}
    return (
        Pad("1", "upper", radius="r", k="k1", d="d1", preload="N0", k_ip="k_ip1" if kip else math.inf,
            friction=FrictionLaw("coulomb", "mu1"), mount=mount, **extra),
        Pad("2", "lower", radius="r", k="k2", d="d2", preload="N0", k_ip="k_ip2" if kip else math.inf,
            friction=FrictionLaw("coulomb", "mu2"), mount=mount, **extra),
    )  # fmt: skip


def _pad_values(kip: bool = True) -> dict[str, float]:
    v = {"r": 0.13, "k1": 6e6, "k2": 6e6, "d1": 5.0, "d2": 5.0, "N0": 3600.0, "mu1": 0.5, "mu2": 0.5}
    if kip:
        v.update(k_ip1=1e8, k_ip2=1e8)
    return v


def _paper_2dof() -> ModelSpec:
    return ModelSpec(
        "paper-2dof", Disk(), _paper_pads(), parameters={**paper_parameters(), **_pad_values()},
        description="The paper's general asymmetric 2-DOF model: massless pads, 3-D Coulomb friction, "
        "tangential springs (quasi-static pads).", reference="paper, eqs. (1)-(48)",
    )  # fmt: skip


def _minimal() -> ModelSpec:
    pads = (
        Pad("1", "upper", k="k", d="d", friction=FrictionLaw("coulomb", "mu")),
        Pad("2", "lower", k="k", d="d", friction=FrictionLaw("coulomb", "mu")),
    )
    par = {**paper_parameters(), "r": 0.13, "k": 6e6, "d": 5.0, "N0": 3600.0, "mu": 0.5}
    return ModelSpec("minimal", Disk(), pads, parameters=par,
                     description="Symmetric supports, rigid tangential supports (eq. 55), equal friction.",
                     reference="paper eq. (54); its ref. [6] (minimal model)")  # fmt: skip


def _in_plane_pad() -> ModelSpec:
    pads = (
        Pad("1", "upper", k="k", d=0.0, k_ip="k_ip", friction=FrictionLaw("coulomb", "mu")),
        Pad("2", "lower", k="k", d=0.0, k_ip="k_ip", friction=FrictionLaw("coulomb", "mu")),
    )
    par = {**paper_parameters(), "d_t": 0.0, "r": 0.13, "k": 6e6, "N0": 3600.0, "mu": 0.5, "k_ip": 1e8}
    del par["d_t"]
    return ModelSpec("in-plane-pad", Disk(d_t=0.0), pads, parameters=par,
                     description="Tangential pad springs (in-plane pad vibration, quasi-static massless pads), "
                     "no dampers, symmetric.", reference="paper's ref. [7]")  # fmt: skip


def _six_dof() -> ModelSpec:
    par = {**paper_parameters(), **_pad_values(), "m_p": 0.5, "k_c": 1e9, "d_c": 20.0, "d_ip": 10.0}
    return ModelSpec("six-dof", Disk(), _paper_pads(mass=True), parameters=par,
                     description="Pads of mass m_p with a normal DOF (contact stiffness k_c) and a tangential "
                     "DOF (spring k_ip): 2 disk + 2x2 pad DOFs.",
                     reference="in the spirit of the paper's ref. [5] (6-DOF model)")  # fmt: skip


def _eight_dof() -> ModelSpec:
    par = {**paper_parameters(), **_pad_values(), "m_p": 0.5, "k_c": 1e9, "d_c": 20.0, "d_ip": 10.0, "m_c": 3.0, "k_cn": 5e7,
           "k_ct": 5e7, "d_cn": 100.0, "d_ct": 100.0}
    cal = Caliper("caliper", mass="m_c", k_n="k_cn", d_n="d_cn", k_t="k_ct", d_t="d_ct")
    return ModelSpec("eight-dof", Disk(), _paper_pads(mass=True, mount="caliper"), calipers=(cal,), parameters=par,
                     description="six-dof with both pads' supports on a floating caliper of mass m_c that moves "
                     "normal and tangential on springs k_cn, k_ct: 8 DOFs.",
                     reference="in the spirit of the paper's ref. [8] (8-DOF model)")  # fmt: skip


def _four_pad() -> ModelSpec:
    pads = tuple(Pad(f"p{a}", "upper", angle_deg=a, k="k", d="d", friction=FrictionLaw("coulomb", "mu"))
                 for a in (0, 90, 180, 270))  # fmt: skip
    par = {**paper_parameters(), "r": 0.13, "k": 6e6, "d": 5.0, "N0": 3600.0, "mu": 0.5}
    return ModelSpec("four-pad", Disk(), pads, parameters=par,
                     description="Four equal massless pads on the upper face at 0, 90, 180 and 270 degrees.",
                     reference="symmetry check of the builder")  # fmt: skip


def _belt() -> ModelSpec:
    pad = Pad("pad", "upper", k=0.0, d=0.0, k_ip="k_ip", d_ip="d_ip", mass="m", dofs=("tangential",),
              friction=FrictionLaw("linear", mu="mu0", slope="slope"))  # fmt: skip
    disk = Disk(Theta=1.0, Phi=1.0, k_t=0.0, d_t=0.0, h_upper="h10", h_lower="h20", tilting=False)
    par = {"h10": 0.01, "h20": 0.01, "Omega": 10.0, "r": 0.1, "N0": 100.0, "k_ip": 1e5, "d_ip": 0.5, "m": 1.0,
           "mu0": 0.6, "slope": 0.1}  # fmt: skip
    return ModelSpec("belt", disk, (pad,), parameters=par,
                     description="A pad mass on a tangential spring/damper, dragged by the non-tilting spinning "
                     "disk (a belt of speed Omega r) with linearly falling friction.",
                     reference="classic negative-slope model (paper's ref. [1])")  # fmt: skip


MODELS = {
    "paper-2dof": _paper_2dof, "minimal": _minimal, "in-plane-pad": _in_plane_pad, "six-dof": _six_dof,
    "eight-dof": _eight_dof, "four-pad": _four_pad, "belt": _belt,
}  # fmt: skip


def get_model(name: str) -> ModelSpec:
    """A built-in model by name (see the module table).

    Parameters
    ----------
    name : str
        One of the keys of :data:`MODELS`: ``"paper-2dof"``, ``"minimal"``,
        ``"in-plane-pad"``, ``"six-dof"``, ``"eight-dof"``, ``"four-pad"``
        or ``"belt"``.

    Returns
    -------
    ModelSpec
        A newly built model with its default parameter values (SI units).

    Raises
    ------
    ParameterError
        If ``name`` is not a built-in model; the message lists the valid names.
    """
    try:
        return MODELS[name]()
    except KeyError:
        raise ParameterError(f"Unknown model '{name}'; built-in models: {', '.join(MODELS)}") from None
