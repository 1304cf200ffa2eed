r"""The per-point quantities of maps and sweeps: one list, one grid evaluator.

A quantity is what maps and sweeps store per parameter point: its name, type,
fill value, attributes (units, meanings) and how it is computed from the
dispatcher's :class:`~.verdict.Verdicts` of a block of points.  Both maps
(:mod:`.maps`, NetCDF) and sweeps (:mod:`brakesqueal.sweep`, Zarr) compute a
block with :func:`evaluate_block` and write the quantities named in it with
the type and attributes given here, so a new quantity is one
:func:`register_quantity` call (``docs/extending.md``).

Built-in quantities (``stable`` and ``status`` are always stored):

============== ===== ================================================================
name           type  meaning
============== ===== ================================================================
stable         bool  certified asymptotically stable silent motion
status         int8  :class:`~brakesqueal.status.PointStatus` code
max_real       f8    largest real part of the eigenvalues [1/s]
frequency      f8    frequency of the least-stable mode [Hz]
margin         f8    damping ratio of the least-stable mode, ``-Re λ/|λ|``
carrier        int8  the mode carrying the verdict (flags: the model's components)
disk_stable    int8  verdict of the disk's modes alone (a massless pad's own mode left out; -1: none)
route          int8  the route of the dispatcher that decided (flags: the routes)
critical_speed f8    first destabilising Ω of the searched range [rad/s]
============== ===== ================================================================
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..status import STATUS_MEANINGS, PointStatus
from .verdict import DECIDED, Points, Verdicts, carrier_labels, decide, route_names

if TYPE_CHECKING:
    from ..codegen.engine import Engine
    from ..model.parameters import ParameterSpace

__all__ = ["Quantity", "Block", "QUANTITIES", "ALWAYS", "register_quantity", "quantity", "attributes",
           "evaluate_block", "needs_eigen", "has_pad_modes"]


@dataclass
class Block:
    """What a quantity is computed from: one block of points and their verdicts.

    Attributes
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The parameter space.
    points : Points
        The block's points.
    verdicts : Verdicts
        Their verdicts (arrays of ``points.shape``).
    status, stable : ndarray
        Working copies of the verdicts' status and stable flags; a quantity may mark a point undecided
        (``critical_speed`` does where its search is not complete).
    options : dict
        Options of the map or study (``critical_speed_range``).
    """

    engine: Engine
    space: ParameterSpace
    points: Points
    verdicts: Verdicts
    status: np.ndarray
    stable: np.ndarray
    options: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Quantity:
    """One per-point quantity of maps and sweeps.

    Attributes
    ----------
    name : str
        The variable's name in files and datasets.
    dtype : str
        NumPy type (``"bool"``, ``"i1"``, ``"f8"``; large maps store ``f8`` as ``f4``).
    fill : Any
        Value of points not computed.
    attrs : Mapping[str, Any]
        Variable attributes (``units``, ``long_name``, flags).
    compute : callable
        ``compute(block) -> ndarray`` of ``block.points.shape``.
    eigen : bool
        Whether it needs ``max_real`` and the frequency (the dispatcher computes them only then).
    labels : callable, optional
        ``labels(engine) -> tuple of str``: the meanings of an integer flag variable's codes (its
        ``flag_values``/``flag_meanings`` attributes).
    """

    name: str
    dtype: str
    fill: Any
    attrs: Mapping[str, Any]
    compute: Callable[[Block], np.ndarray]
    eigen: bool = False
    labels: Callable[[Engine], tuple[str, ...]] | None = None


#: Every quantity, in storage order.
QUANTITIES: dict[str, Quantity] = {}
#: Stored whatever is asked for.
ALWAYS = ("stable", "status")


def register_quantity(q: Quantity) -> None:
    """Add a quantity (maps and sweeps can then store it by name).

    Parameters
    ----------
    q : Quantity
        The quantity; its name must be new.

    Raises
    ------
    ValueError
        A quantity of that name exists.
    """
    if q.name in QUANTITIES:
        raise ValueError(f"a quantity named {q.name!r} is registered already")
    QUANTITIES[q.name] = q


def quantity(name: str) -> Quantity:
    """The registered quantity ``name``.

    Parameters
    ----------
    name : str
        Its name.

    Returns
    -------
    Quantity

    Raises
    ------
    ParameterError
        An unknown name (the message lists the known ones).
    """
    if name not in QUANTITIES:
        from ..errors import ParameterError

        raise ParameterError(f"unknown quantity {name!r}; allowed: {', '.join(QUANTITIES)}", parameter=name)
    return QUANTITIES[name]


def attributes(name: str, engine: Engine | None = None) -> dict[str, Any]:
    """The attributes of a quantity's variable (flags named for the model where the codes are model-specific).

    Parameters
    ----------
    name : str
        The quantity.
    engine : Engine, optional
        The model's engine (for ``carrier``'s labels).

    Returns
    -------
    dict
    """
    q = quantity(name)
    out = dict(q.attrs)
    if q.labels is not None and engine is not None:
        labels = q.labels(engine)
        out["flag_values"] = np.arange(len(labels), dtype=np.int8)
        out["flag_meanings"] = " ".join(lab.replace(" ", "_") for lab in labels)
    return out


def needs_eigen(names: tuple[str, ...]) -> bool:
    """Whether any of the quantities needs ``max_real`` and the frequency.

    Parameters
    ----------
    names : tuple of str
        Quantity names.

    Returns
    -------
    bool
    """
    return any(quantity(n).eigen for n in names)


def evaluate_block(engine: Engine, space: ParameterSpace, points: Points, names: tuple[str, ...], *,
                   modes: str = "all", options: dict[str, Any] | None = None) -> dict[str, np.ndarray]:
    """The one grid evaluator of maps and sweeps: the verdicts of a block of points and the quantities asked for.

    Parameters
    ----------
    engine : Engine
        The model's engine.
    space : ParameterSpace
        The parameter space.
    points : Points
        The block (a grid or samples).
    names : tuple of str
        Quantities to compute besides ``stable`` and ``status``.
    modes : {"all", "disk"}
        As :func:`~.verdict.decide`.
    options : dict, optional
        Options of quantities (``critical_speed_range``).

    Returns
    -------
    dict of ndarray
        ``stable``, ``status`` and every quantity in ``names``, each of ``points.shape`` and its type.
    """
    # carriers where they cost nothing: a grid of a larger model decided from its characteristic polynomial
    # would pay one inverse iteration per point
    v = decide(engine, space, points, eigen=needs_eigen(names), modes=modes, carriers="cheap")
    block = Block(engine, space, points, v, np.array(v.status, dtype=np.int8), np.array(v.stable, dtype=bool),
                  dict(options or {}))
    out = {}
    for n in names:
        if n in ALWAYS:
            continue
        q = quantity(n)
        out[n] = np.asarray(q.compute(block)).astype(q.dtype, copy=False)
    return {"stable": block.stable, "status": block.status, **out}


# ---------------------------------------------------------------- the built-in quantities
def _margin(b: Block) -> np.ndarray:
    with np.errstate(all="ignore"):
        return np.asarray(-b.verdicts.max_real / np.hypot(b.verdicts.max_real, 2 * np.pi * b.verdicts.frequency))


def _critical_speed(b: Block) -> np.ndarray:
    """First destabilising Ω in the range of every decided point (NaN: none); incomplete searches undecided."""
    from .crossings import critical_speeds_many

    shape = b.points.shape
    out = np.full(shape, np.nan)
    dec = np.flatnonzero(np.isin(b.status, DECIDED))
    if dec.size == 0:
        return out
    ix = np.unravel_index(dec, shape)
    names = b.points.names
    at = {n: b.points.settable_values(n)[ix] for n in names}
    lo, hi = b.options.get("critical_speed_range", (1.0, 1e5))
    roots, dirs, counts, _, cst = critical_speeds_many(b.engine, b.space, at, lo, hi, return_status=True)
    k = np.arange(roots.shape[1])
    onset = (dirs == -1) & (k[None, :] < counts[:, None])
    first = np.argmax(onset, axis=1)
    out[ix] = np.where(onset.any(axis=1), roots[np.arange(roots.shape[0]), first], np.nan)
    bad = cst != int(PointStatus.OK)
    b.status[tuple(a[bad] for a in ix)] = int(PointStatus.UNDECIDED)
    b.stable[tuple(a[bad] for a in ix)] = False
    return out


def has_pad_modes(engine: Engine) -> bool:
    """Whether a model has massless pads whose tangential rates are states (modes of a pad alone).

    Parameters
    ----------
    engine : Engine
        The model's engine.

    Returns
    -------
    bool
    """
    return bool(carrier_labels(engine)[2].size)


def _disk_stable(b: Block) -> np.ndarray:
    """The verdict of the disk's modes alone: 1 stable, 0 unstable, -1 no verdict.

    Equal to ``stable`` wherever the verdict is "stable" or carried by a mode other than a massless pad's own
    tangential rate; the points whose instability a pad's rate carries (or whose carrier is not known) are
    decided again with that mode left out (:func:`~.verdict.decide` with ``modes="disk"``: the same routes).
    """
    v = b.verdicts
    shape = b.points.shape
    out = np.full(shape, -1, dtype=np.int8)
    decided = np.isin(b.status, DECIDED)
    out[decided & b.stable] = 1
    pads = carrier_labels(b.engine)[2]
    unstable = decided & ~b.stable
    again = unstable & (np.isin(v.carrier, pads) | (v.carrier < 0)) if pads.size else np.zeros(shape, dtype=bool)
    out[unstable & ~again] = 0
    flat = np.flatnonzero(again)
    if flat.size:
        ix = np.unravel_index(flat, shape)
        at = {n: np.broadcast_to(b.points.settable_values(n), shape)[ix] for n in b.points.names}
        d = decide(b.engine, b.space, Points.of(b.space, at), eigen=False, modes="disk", carriers="cheap")
        ok = np.isin(d.status, DECIDED)
        out[ix] = np.where(ok & d.stable, 1, np.where(ok, 0, -1)).astype(np.int8).reshape(-1)
    return out


def _route_labels(engine: Engine) -> tuple[str, ...]:
    return route_names()


for _q in (
    Quantity("stable", "bool", False, {"long_name": "silent motion asymptotically stable (certified)",
                                       "flag_values": np.array([0, 1], dtype=np.int8),
                                       "flag_meanings": "unstable stable"},
             lambda b: b.stable),
    Quantity("status", "i1", int(PointStatus.NOT_COMPUTED),
             {"flag_values": np.array([int(s) for s in PointStatus], dtype=np.int8), "flag_meanings": STATUS_MEANINGS},
             lambda b: b.status),
    Quantity("max_real", "f8", np.nan, {"units": "1/s", "long_name": "largest real part of the eigenvalues"},
             lambda b: b.verdicts.max_real, eigen=True),
    Quantity("frequency", "f8", np.nan, {"units": "Hz", "long_name": "frequency of the least-stable mode"},
             lambda b: b.verdicts.frequency, eigen=True),
    Quantity("margin", "f8", np.nan, {"units": "1", "long_name": "damping ratio of the least-stable mode, "
                                                              "-Re(lambda)/|lambda| (> 0: stable)"},
             _margin, eigen=True),
    Quantity("carrier", "i1", -1, {"long_name": "mode carrying the verdict (the component with the largest "
                                                "participation in the least-stable mode; -1: no verdict, or not "
                                                "determined: a larger model's point decided from its "
                                                "characteristic polynomial)"},
             lambda b: b.verdicts.carrier, labels=lambda e: carrier_labels(e)[0]),
    Quantity("disk_stable", "i1", -1, {"long_name": "the disk's modes alone asymptotically stable (certified; a "
                                                    "massless pad's own tangential-rate mode left out; -1: no "
                                                    "verdict)",
                                       "flag_values": np.array([-1, 0, 1], dtype=np.int8),
                                       "flag_meanings": "no_verdict unstable stable"},
             _disk_stable),
    Quantity("route", "i1", 0, {"long_name": "stability route that decided the point (brakesqueal.analysis.verdict; "
                                             "0: none)"},
             lambda b: b.verdicts.method, labels=_route_labels),
    Quantity("critical_speed", "f8", np.nan, {"units": "rad/s", "long_name": "smallest Omega in the searched range "
                                                                            "where the silent motion becomes "
                                                                            "unstable (NaN: none)"},
             _critical_speed),
):
    register_quantity(_q)
