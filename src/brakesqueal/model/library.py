"""Built-in models, each with its assumptions and the reference it follows.

=====================  ====  ==============================================================
name                   DOF   what
=====================  ====  ==============================================================
``paper``              2     the paper's general asymmetric model (massless pads; alias ``paper-2dof``)
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

import os
from functools import lru_cache

from ..errors import ParameterError
from .components import Caliper, Disk, FrictionLaw, ModelSpec, Pad
from .parameters import Preset

__all__ = ["MODELS", "ALIASES", "get_model", "paper_parameters", "resolve_model", "get_preset", "PRESETS",  # noqa: F822
           "preset_names"]


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


#: The paper's 17 parameters in its canonical order, with units and descriptions (Sec. 2, Fig. 1).
PAPER_TABLE: tuple[tuple[str, str], ...] = (
    ("Theta", "disk moment of inertia about a diameter"),
    ("Phi", "disk moment of inertia about its axis"),
    ("k_t", "stiffness of the disk's rotational supports"),
    ("d_t", "damping of the disk's rotational supports"),
    ("k1", "normal support stiffness of the upper pad"),
    ("k2", "normal support stiffness of the lower pad"),
    ("d1", "normal support damping of the upper pad"),
    ("d2", "normal support damping of the lower pad"),
    ("k_ip1", "tangential support stiffness of the upper pad (inf = rigid)"),
    ("k_ip2", "tangential support stiffness of the lower pad (inf = rigid)"),
    ("mu1", "kinetic friction coefficient at the upper contact"),
    ("mu2", "kinetic friction coefficient at the lower contact"),
    ("h10", "distance from O to the upper disk surface"),
    ("h20", "distance from O to the lower disk surface"),
    ("r", "effective braking radius"),
    ("N0", "preload of the pads' normal supports"),
    ("Omega", "spin rate of the disk (reverse rotation is not modelled; mirror the model instead)"),
)

_PAPER_SUPPORTS = {"h": 0.02, "r": 0.13, "k_t": 1.88e7, "d_t": 0.1, "k1": 6e6, "k2": 6e6, "d1": 5.0, "d2": 5.0}
_AUX = {"h": "[m] disk thickness h = h10 + h20 (eq. 58)",
        "mu": "kinetic friction coefficient of both contacts (mu1 = mu2)",
        "k_ip": "[N/m] tangential stiffness of both pads (k_ip1 = k_ip2)",
        "R_disk": "[m] disk radius, for the inertia of eq. 63"}
_SYMMETRIC = {"mu1": "mu", "mu2": "mu", "h10": "h/2", "h20": "h/2", "Phi": "2*Theta"}


def _paper_presets() -> tuple[Preset, ...]:
    fig2 = Preset(
        name="paper-fig2",
        description="symmetric model with tangential pad springs; stability map over k_ip and mu with N0 = 1800/mu",
        reference="paper Sec. 3.1, eqs. 50-53 and the parameters below eq. 55, Fig. 2",
        fixed={**_PAPER_SUPPORTS, "Theta": 0.16, "Omega": "16*pi"},
        free={"mu": 0.5, "k_ip": 1e8},
        tied={**_SYMMETRIC, "k_ip1": "k_ip", "k_ip2": "k_ip", "N0": "1800/mu"},
        auxiliary=_AUX)
    fig3 = Preset(
        name="paper-fig3",
        description="asymmetric friction mu1 != mu2 with O placed so that eq. 49 holds (eq. 57); "
                    "Fig. 3 keeps mu1 + mu2 = 1 (eq. 62)",
        reference="paper Sec. 3.2, eqs. 56-63, Fig. 3",
        fixed={**_PAPER_SUPPORTS, "Phi": 0.32, "N0": 3000.0, "R_disk": 0.15},
        free={"mu1": 0.6, "mu2": 0.4, "k_ip": 1e8, "Omega": "16*pi"},
        tied={"h10": "h*mu2/(mu1+mu2)", "h20": "h*mu1/(mu1+mu2)",
              "Theta": "Phi/2 + Phi/(2*R_disk**2)*(h10-h20)**2", "k_ip1": "k_ip", "k_ip2": "k_ip"},
        auxiliary=_AUX)
    minimal = Preset(
        name="minimal-model",
        description="symmetric minimal model of the paper's ref. [6] with rigid tangential supports "
                    "(k_ip1 = k_ip2 = inf)",
        reference="paper eqs. 54-55 with the parameters of Sec. 3.1",
        fixed={**_PAPER_SUPPORTS, "Theta": 0.16, "k_ip1": "inf", "k_ip2": "inf"},
        free={"mu": 0.5, "N0": 3600.0, "Omega": "16*pi"},
        tied=_SYMMETRIC, auxiliary=_AUX)
    general = Preset(
        name="general",
        description="the general asymmetric model: all 17 parameters free (Fig. 2 values at mu = 0.5, k_ip = 1e8)",
        reference="paper Sec. 2, eqs. 1-48",
        fixed={}, free=dict(paper_parameters_full()), tied={})
    return fig2, fig3, minimal, general


def paper_parameters_full() -> dict[str, float]:
    """All 17 parameters of the paper's model at the Fig. 2 point mu = 0.5, k_ip = 1e8 N/m (N0 = 1800/mu)."""
    return {"Theta": 0.16, "Phi": 0.32, "k_t": 1.88e7, "d_t": 0.1, "k1": 6e6, "k2": 6e6, "d1": 5.0, "d2": 5.0,
            "k_ip1": 1e8, "k_ip2": 1e8, "mu1": 0.5, "mu2": 0.5, "h10": 0.01, "h20": 0.01, "r": 0.13,
            "N0": 3600.0, "Omega": 16 * math.pi}


def _paper() -> ModelSpec:
    return ModelSpec(
        "paper", Disk(), _paper_pads(), parameters=paper_parameters_full(),
        description="The paper's general asymmetric 2-DOF model: rigid disk tilting about O at prescribed spin "
        "Omega (eq. 40), two massless pads with normal springs/dampers, tangential springs and 3-D Coulomb "
        "friction (eqs. 12-34).", reference="paper, eqs. (1)-(48)",
        presets=_paper_presets(), descriptions=dict(PAPER_TABLE),
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
    par = {
        **paper_parameters(),
        **_pad_values(),
        "m_p": 0.5,
        "k_c": 1e9,
        "d_c": 20.0,
        "d_ip": 10.0,
        "m_c": 3.0,
        "k_cn": 5e7,
        "k_ct": 5e7,
        "d_cn": 100.0,
        "d_ct": 100.0,
    }
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
    "paper": _paper, "minimal": _minimal, "in-plane-pad": _in_plane_pad, "six-dof": _six_dof,
    "eight-dof": _eight_dof, "four-pad": _four_pad, "belt": _belt,
}  # fmt: skip


#: Other names of built-in models.
ALIASES = {"paper-2dof": "paper"}


@lru_cache(maxsize=None)
def _built(name: str) -> ModelSpec:
    return MODELS[name]()


def get_model(name: str) -> ModelSpec:
    """A built-in model by name (see the module table).

    Parameters
    ----------
    name : str
        One of the keys of :data:`MODELS` (``"paper"``, ``"minimal"``,
        ``"in-plane-pad"``, ``"six-dof"``, ``"eight-dof"``, ``"four-pad"``,
        ``"belt"``) or an alias (``"paper-2dof"``).

    Returns
    -------
    ModelSpec
        The model with its default parameter values (SI units) and presets.

    Raises
    ------
    ParameterError
        If ``name`` is not a built-in model; the message suggests the closest name.
    """
    from ..suggest import did_you_mean

    from .fe_library import FE_MODELS, fe_model

    key = ALIASES.get(name, name) if isinstance(name, str) else name
    if isinstance(key, str) and key in MODELS:
        return _built(key)
    if isinstance(key, str) and key in FE_MODELS:  # the finite-element benchmarks (coefficient matrices)
        return fe_model(key)  # type: ignore[return-value]  # the parameter interface of a model
    names = [*MODELS, *FE_MODELS]
    raise ParameterError(f"Unknown model {name!r}{did_you_mean(str(name), names)}; built-in models: "
                         f"{', '.join(names)}")


def resolve_model(arg: str) -> ModelSpec:
    """A model from a TOML file path or a built-in model name (the ``--model`` option).

    Parameters
    ----------
    arg : str
        Path of a model TOML file (used when the path exists or ends with
        ``.toml``; see :func:`~brakesqueal.model.io.load_model`), else the
        name of a built-in model.

    Returns
    -------
    ModelSpec

    Raises
    ------
    ParameterError
        If ``arg`` is neither a model file nor a built-in model name, or the
        file cannot be read or describes an invalid model.
    """
    if not isinstance(arg, str):
        raise ParameterError(f"--model must be a model name or a file path; got {arg!r}")
    if os.path.exists(arg) or arg.endswith(".toml"):
        from .io import load_model

        return load_model(arg)
    return get_model(arg)


def _all_presets() -> dict[str, Preset]:
    out: dict[str, Preset] = {}
    for name in MODELS:
        spec = get_model(name)
        for pname in spec.preset_names():
            out.setdefault(pname, spec.get_preset(pname))
    return out


def preset_names() -> list[str]:
    """Names of every built-in preset: the named presets first, then one default preset per built-in model."""
    named = [p.name for m in MODELS for p in get_model(m).presets]
    return named + [m for m in MODELS if m not in named]


def get_preset(name: str) -> Preset:
    """A built-in preset by name (bound to its model).

    Parameters
    ----------
    name : str
        ``"paper-fig2"``, ``"paper-fig3"``, ``"minimal-model"``, ``"general"``
        (presets of the paper's model) or the name of a built-in model (its
        default preset: every parameter free at its default value).

    Returns
    -------
    Preset

    Raises
    ------
    ParameterError
        If there is no such preset; the message suggests the closest name.
    """
    from ..suggest import did_you_mean

    presets = _all_presets()
    key = ALIASES.get(name, name) if isinstance(name, str) else name
    if isinstance(key, str) and key in presets:
        return presets[key]
    names = preset_names()
    raise ParameterError(f"Unknown preset {name!r}{did_you_mean(str(name), names)}; presets: {', '.join(names)}")


def __getattr__(name: str) -> object:
    if name == "PRESETS":
        return _all_presets()
    raise AttributeError(name)
