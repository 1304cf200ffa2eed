"""The explorer's state and computations, without any user-interface code.

The state of a view (:class:`ViewState`: model, preset, parameter values, the
path of the root locus, the map's axes and size, the simulated time) is a
small immutable value that round-trips through the page's URL query
(:meth:`ViewState.to_query`, :meth:`ViewState.from_query`), so a link
reproduces a view.  Parameter values are kept as the texts a user typed (as
for ``--set``) and resolved by :func:`brakesqueal.model.options.resolve_space`,
the function every command uses, so the explorer accepts and refuses exactly
what the command line does.

The computations call the library's public routes only:
:func:`~brakesqueal.analysis.linear.linearize`,
:func:`~brakesqueal.analysis.modes.modes_along`,
:func:`~brakesqueal.analysis.maps.stability_map`,
:func:`~brakesqueal.analysis.crossings.critical_speeds`,
:func:`~brakesqueal.nonlinear.models.hopf_points` and
:func:`~brakesqueal.simulation.simulate`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import ParameterError

if TYPE_CHECKING:
    from ..analysis.modes import ModeTracks
    from ..model.components import ModelSpec
    from ..model.parameters import ParameterSpace
    from ..nonlinear.harmonic import HarmonicBranch
    from ..nonlinear.models import HopfPoint
    from ..nonlinear.squeal import SquealBranch
    from ..results import CriticalSpeedResult, StabilityMap
    from ..simulation.trajectory import Trajectory

__all__ = ["MAX_MAP_POINTS", "MAX_T_END", "LOCUS_POINTS", "AUDIO_RATE", "SliderRange", "ViewState",
           "slider_range", "format_eigenvalue", "leading_eigenvalue", "MapView", "map_view", "LocusView",
           "locus_view", "locus_lines", "critical_speed_text", "hopf_scan", "hopf_text", "SimulationView",
           "simulation_view", "check_map_size", "check_t_end", "Origin", "audio_samples", "default_axes",
           "MAX_SLIDERS", "ROLE_RANK", "important_names", "slider_names", "MAP_FORMATS", "map_file", "locus_file",
           "stability_names", "CyclesView", "cycles_view", "LINK_KEYS", "MAX_LINK_VALUE", "MAX_LINK_SET",
           "MAX_LINK_PARAMS", "REFUSED_KEY", "link_problem", "link_limit_message", "RegionView", "region_view"]

#: Largest number of map points the explorer computes (``brakesqueal map`` has no such cap).
MAX_MAP_POINTS = 1_000_000
#: Largest simulated time [s] the explorer runs (``brakesqueal simulate`` has no such cap).
MAX_T_END = 5.0
#: Points of the root locus along the path.
LOCUS_POINTS = 60
#: Sample rate [Hz] of the simulation output and its audio.
AUDIO_RATE = 44100
#: Largest number of points of a drawn time history (min/max per bucket beyond).
HISTORY_POINTS = 4000
#: The query parameters of a link that the explorer reads (others are ignored, within the limits below).
LINK_KEYS = ("model", "preset", "set", "along", "x", "y", "nx", "ny", "t_end")
#: Query parameter by which the server tells the page that a link was refused (its value: the offending key).
REFUSED_KEY = "refused"
#: Most characters of a link's parameter name or value (``set``: of each of its values).
MAX_LINK_VALUE = 64
#: Most characters of a link's ``set`` (``NAME=VALUE`` pairs separated by commas).
MAX_LINK_SET = 2048
#: Most query parameters of a link.
MAX_LINK_PARAMS = 32


def _plain(text: str) -> bool:
    """Printable ASCII only (no control characters, no non-ASCII digits that ``str.isdigit`` accepts)."""
    return text.isascii() and text.isprintable()


def link_problem(query: Mapping[str, Sequence[str]]) -> str | None:
    """The first query parameter of a link beyond the limits, or None.

    Every name and value must be printable ASCII of at most :data:`MAX_LINK_VALUE` characters (``set`` at
    most :data:`MAX_LINK_SET`, each of its values at most :data:`MAX_LINK_VALUE`), and a link has at most
    :data:`MAX_LINK_PARAMS` parameters.

    Parameters
    ----------
    query : Mapping[str, Sequence[str]]
        Each name of the query with its values.

    Returns
    -------
    str or None
        The offending name if it is one of :data:`LINK_KEYS` or :data:`REFUSED_KEY`, ``"link"`` for the
        query as a whole (too many parameters, an over-long or non-ASCII name, or a value of another
        name); None when the link is within the limits.  :func:`link_limit_message` says it in words.
    """
    known = (*LINK_KEYS, REFUSED_KEY)
    if sum(len(v) for v in query.values()) > MAX_LINK_PARAMS:
        return "link"
    for key, values in query.items():
        if not (_plain(key) and len(key) <= MAX_LINK_VALUE):
            return "link"
        where = key if key in known else "link"
        for value in values:
            if not _plain(value) or len(value) > (MAX_LINK_SET if key == "set" else MAX_LINK_VALUE):
                return where
            if key == "set" and any(len(item) > 2 * MAX_LINK_VALUE + 1 or len(item.partition("=")[2].strip())
                                    > MAX_LINK_VALUE for item in value.split(",")):
                return where
    return None


def link_limit_message(key: str) -> str:
    """One line: what :func:`link_problem` refused (``key``: its result)."""
    limits = (f"printable ASCII text of at most {MAX_LINK_VALUE} characters per name and value (set: at most "
              f"{MAX_LINK_SET} characters), at most {MAX_LINK_PARAMS} parameters")
    if key in (*LINK_KEYS, REFUSED_KEY):
        return f"'{key}' in the link is too long or not plain text; a link holds {limits}"
    return f"the link is too long or not plain text; a link holds {limits}"


@dataclass(frozen=True)
class SliderRange:
    """The range of a parameter's slider.

    Attributes
    ----------
    low, high : float
        Ends of the range (SI unit of the parameter).
    log : bool
        Whether the slider moves in ``log10`` of the value.
    """

    low: float
    high: float
    log: bool

    def to_slider(self, value: float) -> float:
        """Slider position of a value (``log10`` for log ranges), clipped to the range."""
        v = min(max(value, self.low), self.high) if math.isfinite(value) else self.high
        return math.log10(v) if self.log else v

    def from_slider(self, position: float) -> float:
        """Value of a slider position."""
        return 10.0 ** position if self.log else position


def slider_range(space: ParameterSpace, name: str) -> SliderRange:
    """A slider range around the current value of a settable name.

    Positive dimensional values get a log range of two decades each way;
    dimensionless values (friction coefficients, slopes) a linear range from
    0 to at least 1; zero and negative values a linear range.

    Parameters
    ----------
    space : ParameterSpace
        The space (its preset gives units and defaults).
    name : str
        A settable name.

    Returns
    -------
    SliderRange
    """
    try:
        v = space.value(name)
    except ParameterError:
        v = math.nan
    unit = space.preset.unit(name)
    if math.isinf(v):  # a rigid support: a log range of stiffnesses, typed input gives inf
        return SliderRange(1e5, 1e10, True)
    if not math.isfinite(v):
        return SliderRange(0.0, 1.0, False)
    if not unit and v >= 0:
        high = max(1.0, 2.0 * v)
        try:  # a friction coefficient may sit in a denominator (paper-fig2: N0 = 1800/mu)
            space.resolve({name: 0.0})
            low = 0.0
        except ParameterError:
            low = high / 100.0
        return SliderRange(low, high, False)
    if v > 0:
        return SliderRange(v / 100.0, v * 100.0, True)
    if v == 0:
        return SliderRange(0.0, 1.0, False)
    return SliderRange(3.0 * v, -3.0 * v, False)


def format_eigenvalue(lam: complex, digits: int = 6) -> str:
    """An eigenvalue as shown by the explorer: ``"0.183869 + 10927.2i"`` (``digits`` significant digits)."""
    re_, im = float(lam.real), float(lam.imag)
    sign = "+" if im >= 0 else "−"
    return f"{re_:.{digits}g} {sign} {abs(im):.{digits}g}i"


def leading_eigenvalue(eigenvalues: Sequence[complex] | np.ndarray) -> complex:
    """The eigenvalue with the largest real part (of a conjugate pair, the one with ``Im >= 0``)."""
    lam = np.asarray(eigenvalues, dtype=complex)
    if lam.size == 0:
        raise ParameterError("the model has no eigenvalues")
    order = np.lexsort((lam.imag, lam.real))  # by real part, then imaginary part
    return complex(lam[order[-1]])


def check_map_size(nx: int, ny: int) -> None:
    """Raise ParameterError (one line) unless an ``nx × ny`` map is within :data:`MAX_MAP_POINTS`."""
    for what, n in (("x", nx), ("y", ny)):
        if not (isinstance(n, (int, np.integer)) and n >= 2):
            raise ParameterError(f"map points along {what} must be an integer of at least 2; got {n!r}")
    if nx * ny > MAX_MAP_POINTS:
        raise ParameterError(f"map of {nx} × {ny} = {nx * ny:,} points: the explorer computes at most "
                             f"{MAX_MAP_POINTS:,} points; use 'brakesqueal map' for larger maps")


def check_t_end(t_end: float) -> None:
    """Raise ParameterError (one line) unless ``0 < t_end <= MAX_T_END``."""
    if not (isinstance(t_end, (int, float)) and math.isfinite(t_end) and 0 < t_end <= MAX_T_END):
        raise ParameterError(f"simulated time t_end = {t_end!r} s: must be in (0, {MAX_T_END:g}] s in the explorer; "
                             "use 'brakesqueal simulate' for longer runs")


@dataclass(frozen=True)
class ViewState:
    """Everything a link to the explorer reproduces.

    Attributes
    ----------
    model : str
        A built-in model name, or the name of the model given on the command line.
    preset : str
        A preset of the model.
    values : Mapping[str, str]
        Overrides of settable names, as texts (``"0.4"``, ``"inf"``, ``"16*pi"``).
    along : str
        The path parameter of the root locus, Hopf analysis and mode-coupling diagram.
    x, y : str
        The map's axes.
    nx, ny : int
        The map's points along ``x`` and ``y``.
    t_end : float
        Simulated time [s].
    """

    model: str
    preset: str
    values: Mapping[str, str] = field(default_factory=dict)
    along: str = ""
    x: str = ""
    y: str = ""
    nx: int = 400
    ny: int = 250
    t_end: float = 0.5

    def sets(self) -> list[str]:
        """The values as ``--set`` texts."""
        return [f"{k}={v}" for k, v in self.values.items()]

    def with_values(self, changes: Mapping[str, str]) -> ViewState:
        """A copy with more overrides."""
        return replace(self, values={**self.values, **changes})

    def to_query(self) -> dict[str, str]:
        """URL query parameters (``set`` holds ``NAME=VALUE`` pairs separated by commas, as ``--set``)."""
        return {"model": self.model, "preset": self.preset, "set": ",".join(self.sets()), "along": self.along,
                "x": self.x, "y": self.y, "nx": str(self.nx), "ny": str(self.ny), "t_end": f"{self.t_end:g}"}

    @classmethod
    def from_query(cls, query: Mapping[str, str], default: ViewState) -> ViewState:
        """The state of a URL query; missing keys keep ``default``'s (a new model or preset drops its values).

        Raises
        ------
        ParameterError
            A parameter beyond the limits of :func:`link_problem`, a malformed number or ``set`` entry
            (names and values are checked when the state is resolved, :meth:`Origin.space_of`).
        """
        problem = link_problem({k: [v] for k, v in query.items()})
        if problem is not None:
            raise ParameterError(link_limit_message(problem), parameter=problem if problem in LINK_KEYS else None)
        model = query.get("model") or default.model
        preset = query.get("preset") or (default.preset if model == default.model else "")
        same = model == default.model and preset == default.preset
        values: dict[str, str] = dict(default.values) if same else {}
        text = query.get("set")
        if text is not None:
            values = {}
            for item in filter(None, (t.strip() for t in text.split(","))):
                name, sep, value = item.partition("=")
                if not sep or not name.strip() or not value.strip():
                    raise ParameterError(f"malformed set entry {item!r} in the link: expected NAME=VALUE")
                values[name.strip()] = value.strip()

        def integer(key: str, fallback: int) -> int:
            if not query.get(key):
                return fallback
            try:
                return int(query[key])
            except ValueError:
                raise ParameterError(f"'{key}' in the link must be an integer; got {query[key]!r}") from None

        t_end = default.t_end
        if query.get("t_end"):
            try:
                t_end = float(query["t_end"])
            except ValueError:
                raise ParameterError(f"'t_end' in the link must be a number of seconds; got {query['t_end']!r}") \
                    from None
        keep = same or not (query.get("model") or query.get("preset"))
        return cls(model=model, preset=preset, values=values,
                   along=query.get("along") or (default.along if keep else ""),
                   x=query.get("x") or (default.x if keep else ""), y=query.get("y") or (default.y if keep else ""),
                   nx=integer("nx", default.nx), ny=integer("ny", default.ny), t_end=t_end)


#: Most parameter sliders the page shows at first; a model's other free names are behind "more parameters".
MAX_SLIDERS = 8
#: Rank of a parameter role in :func:`important_names` (lower first): the spin rate, the friction coefficients,
#: the pads' tangential stiffnesses, the other stiffnesses; any other friction field (a slope), the preload.
#: Every other role (inertias, masses, dampings, geometry) comes after these, in the model's order.
ROLE_RANK: Mapping[str, int] = {
    "disk.Omega": 0, "friction.mu": 1, "pad.k_ip": 2,
    "pad.k": 3, "disk.k_t": 3, "caliper.k_n": 3, "caliper.k_t": 3, "pad.k_c": 3,
}
_OTHER_FRICTION, _PRELOAD, _REST = 4, 5, 6


def _role_rank(key: str) -> int:
    if key in ROLE_RANK:
        return ROLE_RANK[key]
    if key.startswith("friction."):
        return _OTHER_FRICTION
    return _PRELOAD if key == "pad.preload" else _REST


def important_names(space: ParameterSpace, names: Sequence[str]) -> list[str]:
    """``names`` ordered by what an engineer varies first: by the rank of their roles (:data:`ROLE_RANK`).

    The spin rate ``Omega``, the friction coefficients, the pads' tangential
    stiffnesses ``k_ip``, the other stiffnesses, other friction fields, the
    preload; then the rest (inertias ``Theta``/``Phi``, masses, dampings,
    geometry).  Names of equal rank keep their order in ``names``; a name of
    no known role (a preset's derived name) counts as the rest.

    Parameters
    ----------
    space : ParameterSpace
        The space (its model gives the roles).
    names : Sequence[str]
        Settable names.

    Returns
    -------
    list of str
    """
    from ..model.roles import parameter_roles

    uses = parameter_roles(space.model).uses
    rank = {n: min((_role_rank(role.key) for role, _ in uses.get(n, ())), default=_REST) for n in names}
    return sorted(names, key=lambda n: rank[n])  # (a stable sort)


def slider_names(space: ParameterSpace) -> tuple[list[str], list[str]]:
    """The free names whose sliders the page shows at first, and the others (behind "more parameters").

    A preset with at most :data:`MAX_SLIDERS` free names shows them all, in its order; a larger one (a model
    file's default preset frees every parameter) shows its :data:`MAX_SLIDERS` most :func:`important_names`.
    """
    free = list(space.preset.free)
    if len(free) <= MAX_SLIDERS:
        return free, []
    ranked = important_names(space, free)
    shown = set(ranked[:MAX_SLIDERS])
    return [n for n in ranked if n in shown], [n for n in free if n not in shown]


def default_axes(space: ParameterSpace) -> tuple[str, str, str]:
    """Default ``(along, x, y)`` of a space: its two most important free names that move the least-stable eigenvalue.

    A preset with two free names (``paper-fig2``: ``mu``, ``k_ip``) keeps
    them.  With more, they are ordered by :func:`important_names` (so a model
    with a spin rate and a friction coefficient gets the map ``Omega`` ×
    ``mu``, never the disk's inertias ``Theta`` × ``Phi``), and names on which
    the verdict cannot depend at the current point are passed over
    (:func:`stability_names`; e.g. the ``belt``'s disk thickness, whose map
    would be uniformly unstable).  The root locus runs along ``y``.
    """
    names = list(space.settable())
    free = list(space.preset.free) or names
    if len(free) > 2:
        free = important_names(space, free)
        free = stability_names(space, free) or free
    if len(free) > 2:
        x, y = free[0], free[1]
    elif len(free) == 2:
        x, y = free[1], free[0]
    else:
        others = [n for n in names if n != free[0]]
        x, y = (others[0] if others else free[0]), free[0]
    return y, x, y


def stability_names(space: ParameterSpace, names: list[str]) -> list[str]:
    """The names (in their order) whose slider range's ends move the least-stable eigenvalue or the status.

    One batched :func:`~brakesqueal.analysis.points.evaluate` of the two ends
    of every name's :func:`slider_range` with the others at their current
    values.  Empty when the current point itself is not decided.
    """
    from ..api import evaluate
    from ..errors import BrakesquealError

    k = len(names)
    base = {n: space.value(n) for n in names}
    cols = {n: np.full(2 * k + 1, base[n], dtype=float) for n in names}
    for i, n in enumerate(names):
        r = slider_range(space, n)
        cols[n][2 * i:2 * i + 2] = (r.low, r.high)
    try:
        pts = evaluate(space, cols)
    except BrakesquealError:
        return []
    if pts.status[-1] > 1:
        return []
    ref = float(pts.max_real[-1])
    tol = 1e-9 * max(abs(ref), 1e-300)
    moved = (pts.status[:-1] != pts.status[-1]) | (np.abs(np.nan_to_num(pts.max_real[:-1], nan=np.inf) - ref) > tol)
    return [n for i, n in enumerate(names) if moved[2 * i] or moved[2 * i + 1]]


# ---------------------------------------------------------------------------------------------- root locus
@dataclass(frozen=True)
class LocusView:
    """The eigenvalues at the current point and along the path.

    Attributes
    ----------
    eigenvalues : ndarray of complex
        At the current point [1/s].
    leading : complex
        :func:`leading_eigenvalue` of ``eigenvalues``.
    tracks : ModeTracks or None
        The modes along the path (``None`` when the path could not be computed; see ``message``).
    message : str
        Why the path is missing, else ``""``.
    """

    eigenvalues: np.ndarray
    leading: complex
    tracks: ModeTracks | None
    message: str = ""


def locus_view(space: ParameterSpace, along: str, rng: SliderRange, num: int = LOCUS_POINTS, *,
               tracks: ModeTracks | None = None,
               path: bool = True) -> LocusView:
    """Linearize at the current point and track every mode along ``along`` over ``rng``.

    Parameters
    ----------
    space : ParameterSpace
        The current point.
    along : str
        The path parameter.
    rng : SliderRange
        The path.
    num : int
        Points of the path.
    tracks : ModeTracks, optional
        The modes along the path when known (the path does not depend on the
        current value of ``along``): reused instead of recomputed.
    path : bool
        Compute the path (``False``: only the current eigenvalues, ``tracks`` stays as given).

    Raises
    ------
    ParameterError, SilentMotionError
        At the current point (errors along the path are reported in ``message``).
    """
    from ..api import linearize, modes_along
    from ..errors import BrakesquealError

    lm = linearize(space.resolve({}))
    lam = np.asarray(lm.eigenvalues, dtype=complex)
    if tracks is not None or not path:
        return LocusView(lam, leading_eigenvalue(lam), tracks)
    try:
        tracks = modes_along(space, along, rng.low, rng.high, num=num, log=rng.log)
        message = ""
    except BrakesquealError as exc:
        tracks, message = None, f"root locus along {along}: {exc}"
    return LocusView(lam, leading_eigenvalue(lam), tracks, message)


def locus_lines(values: np.ndarray, eigenvalues: np.ndarray) -> dict[str, np.ndarray]:
    """The modes along a path as one polyline per quantity, the modes separated by NaN.

    One float64 array per quantity (sent to the browser as one binary buffer
    and drawn as one line that breaks at the NaNs) instead of a list of
    lists per mode.

    Parameters
    ----------
    values : ndarray, shape (n,)
        The path parameter's values.
    eigenvalues : ndarray of complex, shape (n, m)
        Mode ``k`` along the path in column ``k``.

    Returns
    -------
    dict
        ``value``, ``re``, ``im`` and ``freq`` (``|Im λ| / 2π`` [Hz]), each of
        length ``m (n + 1) - 1``: mode ``k`` at ``[k (n + 1), k (n + 1) + n)``.
    """
    lam = np.asarray(eigenvalues, dtype=complex)
    if lam.ndim != 2 or lam.size == 0:
        return {k: np.empty(0) for k in ("value", "re", "im", "freq")}
    n, m = lam.shape
    v = np.asarray(values, dtype=float).reshape(n, 1)

    def flat(a: np.ndarray) -> np.ndarray:
        return np.vstack([a, np.full((1, m), np.nan)]).T.ravel()[:-1]

    return {"value": flat(np.repeat(v, m, axis=1)), "re": flat(lam.real), "im": flat(lam.imag),
            "freq": flat(np.abs(lam.imag) / (2 * math.pi))}


# ---------------------------------------------------------------------------------------------- map
@dataclass(frozen=True)
class MapView:
    """A stability map prepared for drawing (arrays indexed ``[y, x]``).

    Attributes
    ----------
    x, y : ndarray
        Grid values of the axes (SI units).
    x_log, y_log : bool
        Whether the axes are logarithmic.
    max_real : ndarray
        Largest real part [1/s] (NaN where the status is not decided).
    stable : ndarray of bool
        Certified verdicts.
    status : ndarray of int8
        :class:`~brakesqueal.status.PointStatus` codes.
    boundary_x, boundary_y : ndarray
        The stored refined boundary (curves separated by NaN; empty if none).
    method : str
        The map's route.
    pad_only : ndarray of bool
        Points whose disk modes are certified stable while a massless pad's own 0 Hz mode is unstable (the
        map's ``disk_stable``; drawn apart, not as squeal).
    """

    x: np.ndarray
    y: np.ndarray
    x_log: bool
    y_log: bool
    max_real: np.ndarray
    stable: np.ndarray
    status: np.ndarray
    boundary_x: np.ndarray
    boundary_y: np.ndarray
    method: str
    result: StabilityMap | None = field(default=None, compare=False, repr=False)
    pad_only: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), dtype=bool), compare=False, repr=False)


def map_view(space: ParameterSpace, x: str, y: str, rx: SliderRange, ry: SliderRange, nx: int, ny: int, *,
             progress: Callable[[float], None] | None = None) -> MapView:
    """The stability map over ``x`` and ``y`` (the library's :func:`~brakesqueal.analysis.maps.stability_map`).

    Raises
    ------
    ParameterError
        Equal or tied axes, too many points (:data:`MAX_MAP_POINTS`).
    """
    from ..analysis.maps import Axis
    from ..api import stability_map

    check_map_size(nx, ny)
    if x == y:
        raise ParameterError(f"the map's axes must differ; both are '{x}'")
    ax = Axis(x, rx.low, rx.high, nx, rx.log)
    ay = Axis(y, ry.low, ry.high, ny, ry.log)
    m: StabilityMap = stability_map(space, ax, ay, progress=progress)
    ds = m.data
    stable = ds["stable"].transpose(y, x).values
    status = ds["status"].transpose(y, x).values
    mr = ds["max_real"].transpose(y, x).values.astype(float)
    mr = np.where(status <= 1, mr, np.nan)
    bx = ds[f"boundary_{x}"].values if f"boundary_{x}" in ds else np.empty(0)
    by = ds[f"boundary_{y}"].values if f"boundary_{y}" in ds else np.empty(0)
    pad_only = np.zeros(stable.shape, dtype=bool)
    if "disk_stable" in ds:
        pad_only = (status <= 1) & ~stable.astype(bool) & (ds["disk_stable"].transpose(y, x).values == 1)
    return MapView(ds[x].values, ds[y].values, rx.log, ry.log, mr, stable, status, np.asarray(bx, dtype=float),
                   np.asarray(by, dtype=float), str(ds.attrs.get("method", "")), m, pad_only)


#: Formats of an exported map: its writer's file suffix.
MAP_FORMATS: Mapping[str, str] = {"netcdf": "nc", "csv": "csv"}


def map_file(mv: MapView, fmt: str) -> bytes:
    """The map of a view as a file: the library's own writers (:meth:`~brakesqueal.results.StabilityMap.to_netcdf`,
    :meth:`~brakesqueal.results.StabilityMap.to_csv`).

    Parameters
    ----------
    mv : MapView
        A view made by :func:`map_view`.
    fmt : {"netcdf", "csv"}
        The format.

    Returns
    -------
    bytes

    Raises
    ------
    ParameterError
        An unknown format, or a view without its map.
    """
    import tempfile
    from pathlib import Path

    if fmt not in MAP_FORMATS:
        raise ParameterError(f"map format must be one of {', '.join(MAP_FORMATS)}; got {fmt!r}")
    if mv.result is None:
        raise ParameterError("this map view holds no map to export")
    with tempfile.TemporaryDirectory(prefix="brakesqueal-export-") as tmp:
        path = str(Path(tmp) / f"map.{MAP_FORMATS[fmt]}")
        (mv.result.to_netcdf if fmt == "netcdf" else mv.result.to_csv)(path)
        return Path(path).read_bytes()


def locus_file(tracks: ModeTracks) -> bytes:
    """The modes along the root locus's path as CSV, one row per (path value, mode): the columns of
    :meth:`~brakesqueal.analysis.modes.ModeTracks.to_xarray` (``real`` [1/s], ``frequency`` [Hz], ...)."""
    ds = tracks.to_xarray()
    return str(ds.to_dataframe().reset_index().to_csv(index=False)).encode("utf-8")


# ---------------------------------------------------------------------------------------------- speeds, Hopf
def critical_speed_text(space: ParameterSpace) -> str:
    """One line: the critical speeds of the current point (:func:`~brakesqueal.analysis.crossings.critical_speeds`)."""
    from ..analysis.crossings import omega_name
    from ..api import critical_speeds
    from ..errors import BrakesquealError

    try:
        name = omega_name(space)
        r: CriticalSpeedResult = critical_speeds(space)
    except BrakesquealError as exc:
        return f"critical speed: {exc}"
    if not r.crossings:
        state = "stable" if r.stable_at_start else "unstable"
        return f"critical speed: none in [{r.start:g}, {r.stop:g}] rad/s ({state} throughout)"
    parts = [f"{v:.6g} rad/s ({d})" for v, d in r.crossings]
    crit = "" if r.Omega_crit is None else f"{name}_crit = {r.Omega_crit:.6g} rad/s; "
    certain = "" if r.Omega_crit_certain else " (not certain: undecided ranges)"
    start = "" if r.stable_at_start else f"unstable at {r.start:g} rad/s; "
    return f"critical speed: {start}{crit}changes at " + ", ".join(parts) + certain


def hopf_scan(space: ParameterSpace, along: str, rng: SliderRange) -> list[HopfPoint] | str:
    """Every Hopf point along the path (:func:`~brakesqueal.nonlinear.models.hopf_points`), or why not (a line)."""
    from ..analysis.maps import Axis
    from ..errors import BrakesquealError
    from ..api_nonlinear import hopf_points

    try:
        return list(hopf_points(space, Axis(along, rng.low, rng.high, 2, rng.log)))
    except BrakesquealError as exc:
        return f"Hopf: {exc}"


def hopf_text(points: list[HopfPoint] | str, along: str, current: float, rng: SliderRange) -> str:
    """One line: the Hopf point nearest ``current`` among :func:`hopf_scan`'s, its criticality and amplitude."""
    if isinstance(points, str):
        return points
    if not points:
        return f"Hopf: no stability change along {along} in [{rng.low:.4g}, {rng.high:.4g}]"
    if rng.log and current > 0:
        hp = min(points, key=lambda h: abs(math.log(h.value / current)))
    else:
        hp = min(points, key=lambda h: abs(h.value - current))
    if hp.hopf is None:
        return f"Hopf: {hp.direction} crossing at {along} = {hp.value:.6g}; {hp.message}"
    h = hp.hopf
    side = (f"{along} > {h.p0:.6g}" if h.side > 0 else f"{along} < {h.p0:.6g}") if h.side else "?"
    names = tuple(h.state_names or ())
    amp = ""
    if names:
        a = float(h.amplitude_coefficients[0])
        dp = abs(current - h.p0)
        here = dp > 0 and h.side != 0 and (h.side > 0) == (current > h.p0) and h.criticality == "supercritical"
        loss = hp.contact_loss  # the leading-order prediction of the first lift-off, as `brakesqueal hopf` prints
        lifted = loss is not None and here and abs(current - h.p0) >= abs(loss - h.p0)
        amp = (f"; predicted amplitude of {names[0]} ≈ {a:.3g}·sqrt(|{along} − {h.p0:.4g}|)"
               + (f" = {a * math.sqrt(dp):.3g} here" if here and not lifted else ""))
        if loss is not None:
            amp += (f"; a pad lifts off at {along} ≈ {loss:.6g} (predicted)"
                    + (": the prediction does not hold here" if lifted else ""))
    return (f"Hopf at {along} = {h.p0:.6g} ({hp.direction}, {h.frequency0_hz:.6g} Hz): {h.criticality}, "
            f"l1 = {h.l1:.3g}; cycles for {side}{amp}")


# ---------------------------------------------------------------------------------------------- simulation
@dataclass(frozen=True)
class SimulationView:
    """A simulation prepared for drawing and listening.

    Attributes
    ----------
    t, x : ndarray
        Time history of the first coordinate's deviation (at most :data:`HISTORY_POINTS` points).
    coordinate : str
        Its name.
    f, spectrum : ndarray
        Amplitude spectrum (Hz, amplitude).
    audio : ndarray of int16
        The squeal at :data:`AUDIO_RATE` (normalized to 90 % full scale).
    duration : float
        Simulated duration [s] (``audio.size / AUDIO_RATE``).
    summary : str
        One line: status, frequency, growth rate, final amplitude.
    """

    t: np.ndarray
    x: np.ndarray
    coordinate: str
    f: np.ndarray
    spectrum: np.ndarray
    audio: np.ndarray
    duration: float
    summary: str


def _decimate(t: np.ndarray, x: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """At most ``2 n`` points keeping each bucket's minimum and maximum (the envelope stays visible)."""
    if t.size <= 2 * n:
        return t, x
    k = t.size // n
    m = (t.size // k) * k
    tb, xb = t[:m].reshape(-1, k), x[:m].reshape(-1, k)
    i_min, i_max = xb.argmin(axis=1), xb.argmax(axis=1)
    first = np.minimum(i_min, i_max)
    second = np.maximum(i_min, i_max)
    rows = np.arange(tb.shape[0])
    tt = np.column_stack([tb[rows, first], tb[rows, second]]).ravel()
    xx = np.column_stack([xb[rows, first], xb[rows, second]]).ravel()
    return tt, xx


def audio_samples(velocity: np.ndarray) -> np.ndarray:
    """16-bit PCM of a velocity signal: mean removed, normalized to 90 % full scale (as :meth:`Trajectory.to_wav`)."""
    v = np.asarray(velocity, dtype=float)
    v = np.where(np.isfinite(v), v, 0.0)
    v = v - v.mean() if v.size else v
    peak = float(np.abs(v).max()) if v.size else 0.0
    if peak == 0:
        return np.zeros(v.size, dtype=np.int16)
    return np.round(v / peak * 0.9 * 32767).astype(np.int16)


def simulation_view(space: ParameterSpace, t_end: float, *,
                    progress: Callable[[float], None] | None = None) -> SimulationView:
    """Integrate the nonlinear equations for ``t_end`` seconds (:func:`brakesqueal.simulation.simulate`).

    Raises
    ------
    ParameterError
        ``t_end`` outside ``(0, MAX_T_END]``, or bad parameters.
    SilentMotionError
        If the silent motion does not exist.
    """
    from ..api_nonlinear import simulate

    check_t_end(t_end)
    tr: Trajectory = simulate(space.resolve({}), float(t_end), sample_rate=float(AUDIO_RATE), progress=progress)
    from ..model.components import coordinate_unit

    j = tr.main_coordinate  # the coordinate that carries the motion (q1 or q2, or a pad's displacement)
    name = tr.coords[j]
    unit = coordinate_unit(name)
    t, x = _decimate(np.asarray(tr.t, dtype=float), np.asarray(tr.dq[:, j], dtype=float), HISTORY_POINTS)
    if tr.t.size >= 16:
        f, X = tr.spectrum(j)
    else:
        f, X = np.empty(0), np.empty(0)
    audio = audio_samples(tr.audio_velocity()[0]) if tr.t.size >= 2 else np.zeros(0, dtype=np.int16)
    s = tr.summary
    a = tr.final_amplitudes().get(name, math.nan)
    amp = f"{a:.3g} {unit}" if math.isfinite(a) else "n/a"
    summary = (f"simulation {tr.status}: f = {s.frequency_hz:.6g} Hz, growth rate = {s.growth_rate:.4g} 1/s, "
               f"final amplitude of {name} = {amp}; {tr.stop_reason}")
    return SimulationView(t, x, f"{name} − {name}₀ [{unit}]", np.asarray(f), np.asarray(X), audio,
                          audio.size / AUDIO_RATE, summary)


# ---------------------------------------------------------------------------------------------- resolution
@dataclass(frozen=True)
class Origin:
    """What the explorer was started with: the command line's parameter space.

    Attributes
    ----------
    space : ParameterSpace
        From :func:`brakesqueal.model.options.resolve_space` (``--model/--preset/--params/--set``).
    """

    space: ParameterSpace

    def initial_state(self) -> ViewState:
        """The view of the command line's space (its overrides as texts, default axes)."""
        along, x, y = default_axes(self.space)
        values = {k: (v if isinstance(v, str) else repr(float(v))) for k, v in self.space.values.items()}
        return ViewState(model=self.space.model.name, preset=self.space.label, values=values, along=along, x=x, y=y)

    def models(self) -> list[str]:
        """Model names a view may name: the built-in models and the command line's model."""
        from ..model.library import MODELS

        names = list(MODELS)
        if self.space.model.name not in names:
            names.insert(0, self.space.model.name)
        return names

    def spec(self, name: str) -> ModelSpec:
        """The model of a view.  Only built-in models and the command line's model are allowed (a link
        must not make the server read files).

        Raises
        ------
        ParameterError
            Any other name.
        """
        from ..model.library import get_model
        from ..suggest import did_you_mean

        if name == self.space.model.name:
            return self.space.model
        if name not in self.models():
            raise ParameterError(f"unknown model '{name}'{did_you_mean(name, self.models())}; the explorer offers "
                                 + ", ".join(self.models()))
        return get_model(name)

    def presets(self, model: str) -> list[str]:
        """Preset names of a model (the command line's own preset first when it has no name in the model)."""
        spec = self.spec(model)
        names = list(spec.preset_names())
        if model == self.space.model.name and self.space.label not in names:
            names.insert(0, self.space.label)
        return names

    def space_of(self, state: ViewState) -> ParameterSpace:
        """The validated parameter space of a view: the same resolution as the command line's options.

        Raises
        ------
        ParameterError
            Unknown model, preset or names, invalid values (one line naming the parameter and the allowed range).
        """
        from ..model.options import resolve_space
        from ..model.parameters import ParameterSpace, parse_sets

        spec = self.spec(state.model)
        if spec is self.space.model and state.preset == self.space.label \
                and state.preset not in spec.preset_names():
            space = ParameterSpace(self.space.preset, parse_sets(state.sets(), option=""))
            space.resolve({})
        else:
            space = resolve_space(spec, state.preset or None, None, parse_sets(state.sets(), option=""))
        for name in (state.along, state.x, state.y):
            if name:
                space.check_axis(name)
        return space

    def complete(self, state: ViewState) -> ViewState:
        """``state`` with a preset and axes filled in where the link left them out (raises like :meth:`space_of`)."""
        if not state.preset:
            state = replace(state, preset=self.spec(state.model).get_preset(None).name)
        space = self.space_of(replace(state, along="", x="", y=""))
        along, x, y = default_axes(space)
        names = space.settable()
        return replace(state, along=state.along if state.along in names else along,
                       x=state.x if state.x in names else x, y=state.y if state.y in names else y)


# ---------------------------------------------------------------------------------------------- squeal region
@dataclass(frozen=True)
class RegionView:
    """The squeal region of the map's two parameters (:func:`brakesqueal.region_diagram`), ready to overlay.

    Attributes
    ----------
    hopf : list of (x, y, criticality)
        One entry per Hopf curve: its points' axis values (arrays, in the axes' units) and each point's
        criticality (``"supercritical"``, ``"subcritical"`` or ``"undecided"``).
    special : list of (type, x, y)
        Codimension-2 points (``GH``, ``BT``, ``ZH``, ``HH``).
    folds : list of (x, y)
        Fold-of-cycles curves (their generalised-Hopf point and fold points ``LPC``), where the diagram has them.
    contact : tuple of (x, y)
        Points where the cycles of a slice lose contact before they fold (arrays).
    summary : str
        The diagram's own text summary (its first lines).
    data : dict
        The diagram's JSON (:meth:`~brakesqueal.region.RegionResult.to_dict`).
    """

    hopf: list[tuple[np.ndarray, np.ndarray, list[str]]]
    special: list[tuple[str, float, float]]
    folds: list[tuple[np.ndarray, np.ndarray]]
    contact: tuple[np.ndarray, np.ndarray]
    summary: str
    data: dict[str, Any]


def region_view(space: ParameterSpace, x: str, y: str, rx: SliderRange, ry: SliderRange, *,
                progress: Callable[[float], None] | None = None) -> RegionView:
    """Hopf curves with their criticality, codimension-2 points and fold-of-cycles curves over the map's box.

    The same computation as ``brakesqueal region --x X=LO:HI --y Y=LO:HI`` (without its certified map: the
    explorer's map is drawn beneath), with the map's ranges as the box.

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    x, y : str
        The map's parameters.
    rx, ry : SliderRange
        Their ranges (the box of the diagram).
    progress : callable, optional
        ``progress(fraction)`` (0 at the start, while the fold-of-cycles curves are computed, 1 at the end); an
        exception it raises stops the work (the explorer's Cancel also kills the child process that runs it).

    Returns
    -------
    RegionView

    Raises
    ------
    ParameterError
        A model without nonlinear equations, or axes the diagram refuses (tied or equal names).
    """
    from ..analysis.maps import Axis
    from ..api_nonlinear import region_diagram

    if progress is not None:
        progress(0.0)
    ax, ay = Axis(x, rx.low, rx.high, 2, rx.log), Axis(y, ry.low, ry.high, 2, ry.log)
    r = region_diagram(space, ax, ay, grid=None, progress=progress)
    d = r.to_dict()

    def xy(points: list[dict[str, Any]]) -> tuple[np.ndarray, np.ndarray]:
        return (np.array([p[x] for p in points], dtype=float), np.array([p[y] for p in points], dtype=float))

    hopf = [(*xy(c["points"]), [str(p["criticality"]) for p in c["points"]]) for c in d["hopf_curves"]]
    special = [(str(s["type"]), float(s[x]), float(s[y])) for s in d["special_points"]]
    folds, lost = [], []
    for c in d.get("fold_curves", []):
        pts = c.get("points", [])
        line = [p for p in pts if p.get("kind") in ("GH", "LPC")]
        if sum(p.get("kind") == "LPC" for p in line):
            folds.append(xy(line))
        lost += [p for p in pts if p.get("kind") == "contact_loss"]
    text = r.text().splitlines()
    summary = "; ".join(ln.strip() for ln in text[:4] if ln.strip())
    if progress is not None:
        progress(1.0)
    return RegionView(hopf, special, folds, xy(lost), summary, d)


# ---------------------------------------------------------------------------------------------- limit cycles
@dataclass(frozen=True)
class CyclesView:
    """The limit-cycle branch from the first Hopf point on the path, up to the pads' contact loss.

    Attributes
    ----------
    p : ndarray
        Path values of the branch points.
    amplitude : ndarray
        Tilt amplitude of each cycle [rad] (a non-tilting disk: NaN).
    stable : ndarray of bool
        Stability of each cycle.
    contact_loss : float or None
        Where a pad first loses contact along the branch.
    summary : str
        One line: onset, criticality, squeal range, contact loss, route.
    judged : ndarray of bool or None
        Whether each cycle has a stability verdict (``None``: all have one).
    """

    p: np.ndarray
    amplitude: np.ndarray
    stable: np.ndarray
    contact_loss: float | None
    summary: str
    judged: np.ndarray | None = None


def cycles_view(space: ParameterSpace, along: str, rng: SliderRange, *,
                progress: Callable[[float], None] | None = None) -> CyclesView:
    """Continue the limit cycles along the path with the pads' true tangential dynamics.

    The route is :func:`~brakesqueal.nonlinear.models.cycle_route`'s (bilateral): shooting
    (:func:`~brakesqueal.nonlinear.models.squeal_branch`) where the simulated equations keep every pad's rate,
    harmonic balance (:func:`~brakesqueal.nonlinear.harmonic.harmonic_branch`) where massless Coulomb pads
    with a finite ``k_ip`` would be quasi-static.

    Parameters
    ----------
    space : ParameterSpace
        The model, preset and overrides.
    along : str
        The path's parameter.
    rng : SliderRange
        Its range (the branch is continued within it).
    progress : callable, optional
        ``progress(fraction)``, passed to the branch: called after each accepted branch point with the
        fraction done in ``[0, 1]`` (never decreasing) and with 1.0 at the end; an exception it raises stops
        the continuation and propagates (the explorer's Cancel).

    Returns
    -------
    CyclesView
        The branch's points, stability, contact loss and summary text.

    Raises
    ------
    ParameterError
        No Hopf point with a cycle prediction on the path, or ``progress`` not callable.
    """
    from ..analysis.maps import Axis
    from ..api_nonlinear import limit_cycles
    from ..nonlinear.models import cycle_route

    axis = Axis(along, rng.low, rng.high, 2, rng.log)
    harmonic = cycle_route(space, axis) == "harmonic balance"
    bounded: dict[str, Any] = {"max_points": 25, "max_harmonics": 40} if harmonic else {}  # an interactive view
    br: HarmonicBranch | SquealBranch = limit_cycles(space, axis, progress=progress, **bounded)
    s = br.summary
    rows = list(s.table) if s is not None else []
    p = np.array([float(r["p"]) for r in rows])
    amp = np.array([float(r["tilt_amplitude"]) if r.get("tilt_amplitude") is not None else math.nan for r in rows])
    stable = np.array([bool(r.get("stable")) for r in rows], dtype=bool)
    judged = np.array([r.get("stable") is not None for r in rows], dtype=bool)
    loss = br.contact_loss
    if s is None:
        text = f"limit cycles along {along}: no summary"
    else:
        rng_txt = (f"squeal for {along} in [{s.squeal_range[0]:.6g}, {s.squeal_range[1]:.6g}]"
                   if s.squeal_range else "no squeal range")
        text = (f"limit cycles from the Hopf point at {along} = {s.onset:.6g} ({s.criticality}): {rng_txt}; "
                + (f"a pad loses contact at {along} = {loss:.6g}" if loss is not None else "the pads stay in contact"))
        if harmonic:  # soft massless Coulomb pads: their rates kept exactly
            text += "; exact pads (tangential rates kept): harmonic balance"
    return CyclesView(p, amp, stable, None if loss is None else float(loss), text, judged)
